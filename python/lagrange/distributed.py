"""Rollouts beyond one machine: `lagrange.rollout`'s batch spread over a Ray cluster.

    import lagrange.distributed
    out = lagrange.distributed.rollout("models/mjcf/unitree_go1/scene.xml", states, controls)

The model travels as its source (an absolute file path, or the model text) and load options,
put once in Ray's object store; each worker process loads it once and keeps it for every later
chunk (`_model`). Chunks of rollouts run as Ray tasks, each with `lagrange.rollout` on
`threads_per_task` threads, and the results are gathered in input order: the arrays equal
`lagrange.rollout`'s on the same arguments bit for bit (each rollout steps its own fresh Data).

A file model must be readable at the same absolute path on every node (a shared file system);
otherwise load it with `Model.from_string` (whose text is shipped) or pass the text.

Ray is optional: `pip install ./python[ray]`.
"""

from __future__ import annotations

import math
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from ._lagrange import Model
from ._lagrange import rollout as _rollout

ModelSpec = Tuple[str, str, str, Dict[str, Any]]

# Per worker process: the models loaded so far, by their source and options.
_MODELS: Dict[Tuple, Model] = {}


def _spec_of(model: Model) -> ModelSpec:
    """The (kind, text, path, options) a model pickles as (Model.__reduce__)."""
    _restore, (kind, text, path, options) = model.__reduce__()
    return kind, text, str(path), dict(options)


def _key(spec: ModelSpec) -> Tuple:
    kind, text, path, options = spec
    return (kind, text, path, tuple(sorted((k, repr(v)) for k, v in options.items())))


def _model(spec: ModelSpec) -> Model:
    """The model of `spec`, loaded once per process."""
    key = _key(spec)
    model = _MODELS.get(key)
    if model is None:
        kind, text, path, options = spec
        model = Model._restore(kind, text, path, options)
        _MODELS[key] = model
    return model


def _run_chunk(spec: ModelSpec, states: np.ndarray, controls: Optional[np.ndarray], nstep: int, threads: int):
    """One task: a chunk of rollouts on this worker."""
    return _rollout(_model(spec), states, controls, nstep, threads=threads)


def _as_model(model_or_path: Union[Model, str, os.PathLike], load_options: Optional[dict]) -> Model:
    if isinstance(model_or_path, Model):
        return model_or_path
    return Model.from_file(os.fspath(model_or_path), **(load_options or {}))


def _ray():
    try:
        import ray
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("lagrange.distributed needs Ray: pip install './python[ray]' (or pip install ray)") from e
    return ray


def rollout(
    model_or_path: Union[Model, str, os.PathLike],
    initial_states: np.ndarray,
    controls: Optional[np.ndarray] = None,
    nstep: Optional[int] = None,
    chunk: Optional[int] = None,
    *,
    threads_per_task: int = 1,
    load_options: Optional[dict] = None,
) -> Dict[str, Any]:
    """`lagrange.rollout` over a Ray cluster: same arguments, same result.

    Uses the running Ray if `ray.is_initialized()`, else starts a local one. `chunk` rollouts
    go to each task (default: the batch split in about four tasks per CPU of the cluster);
    each task requests `threads_per_task` CPUs and runs that many threads. `load_options`
    (package_dirs, floating, disable, ...) apply when a path is given.
    """
    ray = _ray()
    model = _as_model(model_or_path, load_options)
    states = np.ascontiguousarray(initial_states, dtype=np.float64)
    if states.ndim != 2:
        raise ValueError(f"initial_states: expected shape (nbatch, nq + nv + na), got {states.shape}")
    nbatch = states.shape[0]
    if controls is not None:
        controls = np.ascontiguousarray(controls, dtype=np.float64)
        if controls.ndim != 3 or controls.shape[0] != nbatch:
            raise ValueError(f"controls: expected shape ({nbatch}, nstep, nu), got {controls.shape}")
        if nstep is None:
            nstep = controls.shape[1]
    if nstep is None:
        raise ValueError("rollout: give nstep or controls")
    if not ray.is_initialized():
        ray.init()
    if chunk is None:
        cpus = max(1, int(ray.cluster_resources().get("CPU", 1)))
        chunk = max(1, math.ceil(nbatch / (4 * cpus)))
    if chunk < 1:
        raise ValueError("chunk must be at least 1")
    if nbatch == 0:
        return _rollout(model, states, controls, nstep, threads=1)
    run = ray.remote(num_cpus=threads_per_task)(_run_chunk)
    spec = ray.put(_spec_of(model))
    starts = list(range(0, nbatch, chunk))
    futures = [
        run.remote(
            spec,
            states[s : s + chunk],
            None if controls is None else controls[s : s + chunk],
            nstep,
            threads_per_task,
        )
        for s in starts
    ]
    parts: List[Dict[str, Any]] = ray.get(futures)
    out: Dict[str, Any] = {}
    for key in ("qpos", "qvel", "act", "time", "sensordata"):
        out[key] = np.concatenate([p[key] for p in parts], axis=0)
    out["error"] = [e for p in parts for e in p["error"]]
    return out


def sweep(
    models: Sequence[Union[Model, str, os.PathLike]],
    initial_states: np.ndarray,
    controls: Optional[np.ndarray] = None,
    nstep: Optional[int] = None,
    *,
    threads_per_task: int = 1,
    load_options: Optional[dict] = None,
) -> List[Dict[str, Any]]:
    """A parameter sweep: the same rollouts (`initial_states`, `controls`) for each of `models`
    (model variants as files, texts loaded with `Model.from_string`, or `Model`s), one Ray task
    per model, results in the order of `models`. The models must share nq, nv, na and nu."""
    ray = _ray()
    loaded = [_as_model(m, load_options) for m in models]
    states = np.ascontiguousarray(initial_states, dtype=np.float64)
    if controls is not None:
        controls = np.ascontiguousarray(controls, dtype=np.float64)
        if nstep is None:
            nstep = controls.shape[1]
    if nstep is None:
        raise ValueError("sweep: give nstep or controls")
    if not ray.is_initialized():
        ray.init()
    run = ray.remote(num_cpus=threads_per_task)(_run_chunk)
    states_ref = ray.put(states)
    controls_ref = ray.put(controls)
    futures = [run.remote(_spec_of(m), states_ref, controls_ref, nstep, threads_per_task) for m in loaded]
    return ray.get(futures)

// Same-run native benchmark, MuJoCo side (validation/README.md, "Native benchmark").
//
//   bench_mujoco STATES ROBOT MODEL.mjb     then commands on stdin: `OP BUDGET_MS`, one a line
//
// MODEL.mjb is the robot compiled by MuJoCo (mujoco 4.0.0 Python bindings, same library) and
// saved by bench_native.py, with constraints, contacts, limits, equality, friction loss, springs,
// dampers, actuation and fluid forces disabled (pure rigid-body dynamics). Only the wheel's
// libmujoco is called here; this file's own flags hardly matter.
//
// Prints JSON lines: `info`, `check` lines (results at the first states, MuJoCo's coordinates),
// `ready` with the operations it knows, then for each command one line with the per-call time
// (µs) of every batch.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <mujoco/mujoco.h>

typedef struct {
  int nq, nv, n;
  double* q;  // n × nq
  double* v;  // n × nv
  double* a;
  double* tau;
} States;

// Reads the block `robot ROBOT engine mujoco` of the states file (format: bench_native.py).
static States read_states(const char* path, const char* robot) {
  FILE* f = fopen(path, "r");
  if (!f) {
    fprintf(stderr, "bench_mujoco: cannot open %s\n", path);
    exit(2);
  }
  char tok[256], name[256], eng[256];
  States st = {0, 0, 0, NULL, NULL, NULL, NULL};
  while (fscanf(f, "%255s", tok) == 1) {
    if (strcmp(tok, "robot") != 0) continue;
    int nq, nv, n;
    if (fscanf(f, "%255s %*s %255s %*s %d %*s %d %*s %d", name, eng, &nq, &nv, &n) != 5) break;
    const int want = strcmp(name, robot) == 0 && strcmp(eng, "mujoco") == 0;
    double* q = malloc(sizeof(double) * (size_t)(n * nq + 1));
    double* v = malloc(sizeof(double) * (size_t)(n * nv + 1));
    double* a = malloc(sizeof(double) * (size_t)(n * nv + 1));
    double* tau = malloc(sizeof(double) * (size_t)(n * nv + 1));
    for (int s = 0; s < n; ++s) {
      for (int i = 0; i < nq; ++i) fscanf(f, "%lf", q + s * nq + i);
      for (int i = 0; i < nv; ++i) fscanf(f, "%lf", v + s * nv + i);
      for (int i = 0; i < nv; ++i) fscanf(f, "%lf", a + s * nv + i);
      for (int i = 0; i < nv; ++i) fscanf(f, "%lf", tau + s * nv + i);
    }
    if (want) {
      st.nq = nq;
      st.nv = nv;
      st.n = n;
      st.q = q;
      st.v = v;
      st.a = a;
      st.tau = tau;
      fclose(f);
      return st;
    }
    free(q);
    free(v);
    free(a);
    free(tau);
  }
  fprintf(stderr, "bench_mujoco: no block for robot %s engine mujoco in %s\n", robot, path);
  exit(2);
}

static double now_us(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec * 1e6 + (double)t.tv_nsec * 1e-3;
}

static const mjModel* m;
static mjData* d;
static States S;
static const char* robot;
static double* res;  // nv
static volatile double g_sink;

static void set_q(int s) { mju_copy(d->qpos, S.q + s * S.nq, S.nq); }
static void set_qv(int s) {
  mju_copy(d->qpos, S.q + s * S.nq, S.nq);
  mju_copy(d->qvel, S.v + s * S.nv, S.nv);
}

// ---- the timed operations: one call at state s; return a value to keep the work alive ----

// FK: body (and geom, site) poses.
static double op_fk(int s) {
  set_q(s);
  mj_kinematics(m, d);
  return d->xpos[3 * (m->nbody - 1)];
}

// RNEA from q, v, a: kinematics, com-based quantities, then mj_rne with the acceleration term.
static double op_rnea(int s) {
  set_qv(s);
  mju_copy(d->qacc, S.a + s * S.nv, S.nv);
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_comVel(m, d);
  mj_rne(m, d, 1, res);
  return res[0];
}

// CRBA from q: kinematics, com-based inertias, mj_crb (M with armature, MuJoCo's sparse format).
static double op_crba(int s) {
  set_q(s);
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_crb(m, d);
  return d->M[0];
}

// Forward dynamics from q, v, tau the way MuJoCo does it (no ABA): CRBA, sparse LᵀDL, bias
// forces by RNE, qacc = M⁻¹ (tau − bias).
static double op_fd(int s) {
  set_qv(s);
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_crb(m, d);
  mj_factorM(m, d);
  mj_comVel(m, d);
  mj_rne(m, d, 0, d->qfrc_bias);
  const double* tau = S.tau + s * S.nv;
  for (int i = 0; i < S.nv; ++i) d->qfrc_smooth[i] = tau[i] - d->qfrc_bias[i];
  mj_solveM(m, d, d->qacc, d->qfrc_smooth, 1);
  return d->qacc[0];
}

// mj_forward with everything but smooth dynamics disabled in the model (sensors, energy off).
static double op_forward(int s) {
  set_qv(s);
  mju_copy(d->qfrc_applied, S.tau + s * S.nv, S.nv);
  mj_forward(m, d);
  return d->qacc[0];
}

// Fixed-state operations: the state is prepared (untimed) once per batch.
static void prep_crb(int s) {
  set_qv(s);
  mju_copy(d->qacc, S.a + s * S.nv, S.nv);
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_comVel(m, d);
  mj_crb(m, d);
}

static double op_factor_solve(int s) {
  mj_factorM(m, d);
  mj_solveM(m, d, res, S.tau + s * S.nv, 1);
  return res[0];
}

static double op_rne_only(int s) {
  (void)s;
  mj_rne(m, d, 1, res);
  return res[0];
}

static double op_crb_only(int s) {
  (void)s;
  mj_crb(m, d);
  return d->M[0];
}

// ---- timing (same method in the three programs) ----

static void emit(const char* op, const double* us, int k) {
  printf("{\"engine\":\"mujoco\",\"robot\":\"%s\",\"op\":\"%s\",\"us\":[", robot, op);
  for (int i = 0; i < k; ++i) printf("%s%.6g", i ? "," : "", us[i]);
  printf("]}\n");
}

// A batch is one call per state (all states in turn) or, with `prepare`, as many calls at one
// state prepared beforehand (untimed); per-call time = batch time / calls. Two warm-up
// batches, then batches until budget_ms has passed (at least 5).
static void time_op(const char* op, double budget_ms, void (*prepare)(int), double (*call)(int)) {
  int cap = 1024, k = 0;
  double* us = malloc(sizeof(double) * (size_t)cap);
  const double start = now_us();
  for (int b = 0; b < 2 || k < 5 || (now_us() - start < budget_ms * 1e3 && k < 100000); ++b) {
    if (prepare) prepare(b % S.n);
    double sink = 0.0;
    const double t0 = now_us();
    for (int s = 0; s < S.n; ++s) sink += call(s);
    const double t1 = now_us();
    g_sink = g_sink + sink;
    if (b >= 2) {
      if (k == cap) {
        cap *= 2;
        us = realloc(us, sizeof(double) * (size_t)cap);
      }
      us[k++] = (t1 - t0) / S.n;
    }
  }
  emit(op, us, k);
  free(us);
}

static void emit_check(const char* what, int s, const double* x, int n) {
  printf("{\"engine\":\"mujoco\",\"robot\":\"%s\",\"check\":\"%s\",\"state\":%d,\"x\":[", robot, what, s);
  for (int i = 0; i < n; ++i) printf("%s%.17g", i ? "," : "", x[i]);
  printf("]}\n");
}

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: bench_mujoco STATES ROBOT MODEL.mjb  (then `OP BUDGET_MS` lines on stdin)\n");
    return 2;
  }
  robot = argv[2];
  mjModel* model = mj_loadModel(argv[3], NULL);
  if (!model) {
    fprintf(stderr, "bench_mujoco: cannot load %s\n", argv[3]);
    return 2;
  }
  m = model;
  S = read_states(argv[1], robot);
  if (S.nq != m->nq || S.nv != m->nv || S.n == 0) {
    fprintf(stderr, "bench_mujoco: %s: states have nq %d nv %d, the model %d %d\n", robot, S.nq, S.nv,
            (int)m->nq, (int)m->nv);
    return 2;
  }
  d = mj_makeData(m);
  res = malloc(sizeof(double) * (size_t)(m->nv + 1));
  double* full = malloc(sizeof(double) * (size_t)(m->nv * m->nv + 1));
  printf("{\"engine\":\"mujoco\",\"robot\":\"%s\",\"info\":{\"nq\":%d,\"nv\":%d,\"nbody\":%d,\"ngeom\":%d,"
         "\"nsite\":%d,\"version\":\"%s\",\"disableflags\":%d,\"enableflags\":%d}}\n",
         robot, (int)m->nq, (int)m->nv, (int)m->nbody, (int)m->ngeom, (int)m->nsite, mj_versionString(),
         (int)m->opt.disableflags, (int)m->opt.enableflags);

  for (int s = 0; s < S.n && s < 4; ++s) {
    op_rnea(s);
    emit_check("rnea", s, res, m->nv);
    op_crba(s);
    mj_fullM(m, d, full);
    emit_check("crba", s, full, m->nv * m->nv);
    op_factor_solve(s);
    emit_check("solve", s, res, m->nv);
    op_fd(s);
    emit_check("aba", s, d->qacc, m->nv);
  }

  static const struct {
    const char* name;
    void (*prepare)(int);
    double (*call)(int);
  } ops[] = {
      {"fk", NULL, op_fk},
      {"rnea", NULL, op_rnea},
      {"crba", NULL, op_crba},
      {"aba", NULL, op_fd},
      {"factor_solve", prep_crb, op_factor_solve},
      {"rne_only", prep_crb, op_rne_only},
      {"crb_only", prep_crb, op_crb_only},
      {"forward", NULL, op_forward},
  };
  const int nops = (int)(sizeof ops / sizeof ops[0]);
  printf("{\"ready\":[");
  for (int i = 0; i < nops; ++i) printf("%s\"%s\"", i ? "," : "", ops[i].name);
  printf("]}\n");
  fflush(stdout);
  char op[64];
  double budget_ms;
  while (scanf("%63s %lf", op, &budget_ms) == 2) {
    int i = 0;
    while (i < nops && strcmp(ops[i].name, op) != 0) ++i;
    if (i == nops) {
      fprintf(stderr, "bench_mujoco: unknown operation %s\n", op);
      return 2;
    }
    time_op(ops[i].name, budget_ms, ops[i].prepare, ops[i].call);
    fflush(stdout);
  }

  free(full);
  free(res);
  mj_deleteData(d);
  mj_deleteModel(model);
  return g_sink == 12345.6789 ? 1 : 0;
}

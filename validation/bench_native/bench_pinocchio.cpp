// Same-run native benchmark, Pinocchio side (validation/README.md, "Native benchmark").
//
//   bench_pinocchio STATES ROBOT MODEL.txt     then commands on stdin: `OP BUDGET_MS`, one a line
//
// MODEL.txt is the robot's pinocchio::Model as a Boost text archive, written by bench_native.py
// with Pinocchio's own parsers (Python bindings of the same pinned version) and read back by
// load_pinocchio_model.cpp. Every timed algorithm is instantiated here from the headers (no
// PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION, libpinocchio_*.so is not linked), so it is compiled
// with this file's flags (-O3 -march=native -DNDEBUG); code built with other -march flags (the
// wheel's libraries) could disagree with it on Eigen's alignment, so none is mixed in.
//
// Prints JSON lines: `info`, `check` lines (results at the first states, for bench_native.py to
// compare across engines in common coordinates), then `ready` with the operations it knows; then
// for each command one line with the per-call time (µs) of every batch. The driver sends the
// same operation to the three programs in turn (interleaved), many times.
#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/cholesky.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

// In libload_pinocchio_model.so (load_pinocchio_model.cpp).
void bench_native_load_model(const char* path, pinocchio::Model& model);

using Model = pinocchio::Model;
using Data = pinocchio::Data;
using Vec = Eigen::VectorXd;

struct State {
  Vec q, v, a, tau;
};

// Reads the block `robot ROBOT engine pinocchio` of the states file (format: bench_native.py).
static std::vector<State> read_states(const char* path, const std::string& robot, int* nq_out, int* nv_out) {
  std::ifstream in(path);
  if (!in) {
    std::fprintf(stderr, "bench_pinocchio: cannot open %s\n", path);
    std::exit(2);
  }
  std::string tok, name, eng;
  int nq, nv, n;
  while (in >> tok) {
    if (tok != "robot") continue;
    in >> name >> tok >> eng >> tok >> nq >> tok >> nv >> tok >> n;
    const bool want = name == robot && eng == "pinocchio";
    std::vector<State> states;
    for (int s = 0; s < n; ++s) {
      State st{Vec(nq), Vec(nv), Vec(nv), Vec(nv)};
      for (int i = 0; i < nq; ++i) in >> st.q[i];
      for (int i = 0; i < nv; ++i) in >> st.v[i];
      for (int i = 0; i < nv; ++i) in >> st.a[i];
      for (int i = 0; i < nv; ++i) in >> st.tau[i];
      if (want) states.push_back(st);
    }
    if (want) {
      *nq_out = nq;
      *nv_out = nv;
      return states;
    }
  }
  std::fprintf(stderr, "bench_pinocchio: no block for robot %s engine pinocchio in %s\n", robot.c_str(), path);
  std::exit(2);
}

static double now_us() {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Timing method shared by the three programs: a batch is one call per state (all states in turn)
// for `per_state` operations, or, for `fixed` ones, as many calls at one state prepared
// beforehand (untimed); per-call time = batch time / calls. Two warm-up batches, then batches
// until budget_ms has passed (at least 5).
static volatile double g_sink = 0.0;

static void emit(const char* robot, const char* op, const std::vector<double>& us) {
  std::printf("{\"engine\":\"pinocchio\",\"robot\":\"%s\",\"op\":\"%s\",\"us\":[", robot, op);
  for (size_t i = 0; i < us.size(); ++i) std::printf("%s%.6g", i ? "," : "", us[i]);
  std::printf("]}\n");
}

template <class Call>
static void time_per_state(const char* robot, const char* op, size_t n, double budget_ms, Call call) {
  std::vector<double> us;
  const double start = now_us();
  for (int b = 0; b < 2 || us.size() < 5 || (now_us() - start < budget_ms * 1e3 && us.size() < 100000); ++b) {
    double sink = 0.0;
    const double t0 = now_us();
    for (size_t s = 0; s < n; ++s) sink += call(s);
    const double t1 = now_us();
    g_sink = g_sink + sink;
    if (b >= 2) us.push_back((t1 - t0) / double(n));
  }
  emit(robot, op, us);
}

template <class Prepare, class Call>
static void time_fixed(const char* robot, const char* op, size_t n, double budget_ms, Prepare prepare, Call call) {
  std::vector<double> us;
  const double start = now_us();
  for (int b = 0; b < 2 || us.size() < 5 || (now_us() - start < budget_ms * 1e3 && us.size() < 100000); ++b) {
    prepare(size_t(b) % n);
    double sink = 0.0;
    const double t0 = now_us();
    for (size_t s = 0; s < n; ++s) sink += call(s);
    const double t1 = now_us();
    g_sink = g_sink + sink;
    if (b >= 2) us.push_back((t1 - t0) / double(n));
  }
  emit(robot, op, us);
}

static void emit_check(const char* robot, const char* what, size_t state, const double* x, long n) {
  std::printf("{\"engine\":\"pinocchio\",\"robot\":\"%s\",\"check\":\"%s\",\"state\":%zu,\"x\":[", robot, what, state);
  for (long i = 0; i < n; ++i) std::printf("%s%.17g", i ? "," : "", x[i]);
  std::printf("]}\n");
}

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: bench_pinocchio STATES ROBOT MODEL.txt  (then `OP BUDGET_MS` lines on stdin)\n");
    return 2;
  }
  const char* robot = argv[2];
  Model model;
  try {
    bench_native_load_model(argv[3], model);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_pinocchio: cannot load %s: %s\n", argv[3], e.what());
    return 2;
  }
  int nq = 0, nv = 0;
  const std::vector<State> states = read_states(argv[1], robot, &nq, &nv);
  if (nq != model.nq || nv != model.nv || states.empty()) {
    std::fprintf(stderr, "bench_pinocchio: %s: states have nq %d nv %d, the model %d %d\n", robot, nq, nv,
                 model.nq, model.nv);
    return 2;
  }
  Data data(model);
  const size_t n = states.size();
  std::printf("{\"engine\":\"pinocchio\",\"robot\":\"%s\",\"info\":{\"nq\":%d,\"nv\":%d,\"njoints\":%d,\"nframes\":%d,"
              "\"version\":\"%s\"}}\n",
              robot, model.nq, model.nv, int(model.njoints), int(model.nframes), PINOCCHIO_VERSION);

  // Results at the first states, in Pinocchio's coordinates (converted by bench_native.py).
  for (size_t s = 0; s < std::min<size_t>(n, 4); ++s) {
    const State& st = states[s];
    Vec tau = pinocchio::rnea(model, data, st.q, st.v, st.a);
    emit_check(robot, "rnea", s, tau.data(), nv);
    pinocchio::crba(model, data, st.q);
    Eigen::MatrixXd M = data.M;
    M.triangularView<Eigen::StrictlyLower>() = M.transpose().triangularView<Eigen::StrictlyLower>();
    emit_check(robot, "crba", s, M.data(), long(nv) * nv);
    pinocchio::cholesky::decompose(model, data);
    Vec x = st.tau;
    pinocchio::cholesky::solve(model, data, x);
    emit_check(robot, "solve", s, x.data(), nv);
    Vec qacc = pinocchio::aba(model, data, st.q, st.v, st.tau);
    emit_check(robot, "aba", s, qacc.data(), nv);
  }

  Vec x(nv);
  std::printf("{\"ready\":[\"fk\",\"rnea\",\"crba\",\"crba_world\",\"aba\",\"aba_world\",\"factor_solve\",\"rnea_derivatives\",\"aba_derivatives\"]}\n");
  std::fflush(stdout);
  char op_buf[64];
  double budget_ms = 0.0;
  while (std::scanf("%63s %lf", op_buf, &budget_ms) == 2) {
    const std::string op(op_buf);
    if (op == "fk") {
      time_per_state(robot, "fk", n, budget_ms, [&](size_t s) {
        pinocchio::framesForwardKinematics(model, data, states[s].q);
        return data.oMf.back().translation()[0];
      });
    } else if (op == "rnea") {
      time_per_state(robot, "rnea", n, budget_ms, [&](size_t s) {
        const State& st = states[s];
        return pinocchio::rnea(model, data, st.q, st.v, st.a)[0];
      });
    } else if (op == "crba") {
      time_per_state(robot, "crba", n, budget_ms,
                     [&](size_t s) { return pinocchio::crba(model, data, states[s].q)(0, nv - 1); });
    } else if (op == "crba_world") {
      time_per_state(robot, "crba_world", n, budget_ms, [&](size_t s) {
        return pinocchio::crba(model, data, states[s].q, pinocchio::Convention::WORLD)(0, nv - 1);
      });
    } else if (op == "aba") {
      time_per_state(robot, "aba", n, budget_ms, [&](size_t s) {
        const State& st = states[s];
        return pinocchio::aba(model, data, st.q, st.v, st.tau)[0];
      });
    } else if (op == "aba_world") {
      time_per_state(robot, "aba_world", n, budget_ms, [&](size_t s) {
        const State& st = states[s];
        return pinocchio::aba(model, data, st.q, st.v, st.tau, pinocchio::Convention::WORLD)[0];
      });
    } else if (op == "factor_solve") {
      // Factor + solve of the M of one state per batch (CRBA untimed), one right-hand side per call.
      time_fixed(
          robot, "factor_solve", n, budget_ms, [&](size_t s) { pinocchio::crba(model, data, states[s].q); },
          [&](size_t s) {
            x = states[s].tau;
            pinocchio::cholesky::decompose(model, data);
            pinocchio::cholesky::solve(model, data, x);
            return x[0];
          });
    } else if (op == "rnea_derivatives") {
      // ∂τ/∂q, ∂τ/∂v (and ∂τ/∂a = M) of RNEA.
      time_per_state(robot, "rnea_derivatives", n, budget_ms, [&](size_t s) {
        const State& st = states[s];
        pinocchio::computeRNEADerivatives(model, data, st.q, st.v, st.a);
        return data.dtau_dq(0, 0);
      });
    } else if (op == "aba_derivatives") {
      // ∂q̈/∂q, ∂q̈/∂v, ∂q̈/∂τ = M⁻¹ of ABA.
      time_per_state(robot, "aba_derivatives", n, budget_ms, [&](size_t s) {
        const State& st = states[s];
        pinocchio::computeABADerivatives(model, data, st.q, st.v, st.tau);
        return data.ddq_dq(0, 0);
      });
    } else {
      std::fprintf(stderr, "bench_pinocchio: unknown operation %s\n", op_buf);
      return 2;
    }
    std::fflush(stdout);
  }
  return 0;
}

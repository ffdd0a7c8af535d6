// Loads a pinocchio::Model from a Boost text archive (Model::saveToText in Pinocchio's Python
// bindings). Built by `run` as a separate shared library, with -O1 and hidden visibility: the
// serialization code is heavy to compile and untimed, and hidden visibility keeps its template
// instances private, so bench_pinocchio's timed code only ever runs its own -O3 instances.
// Same -march and defines as bench_pinocchio.cpp, so both agree on Eigen's alignment.
#include <pinocchio/multibody.hpp>
#include <pinocchio/serialization.hpp>

__attribute__((visibility("default"))) void bench_native_load_model(const char* path, pinocchio::Model& model) {
  model.loadFromText(path);
}

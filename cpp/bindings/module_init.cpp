// The extension's entry point, compiled once for each build of the core (cmake/targets/CMakeLists.txt): _core for
// any CPU, and on x86-64 _core_v3 for x86-64-v3 (AVX2, FMA). Both name themselves rigidfem._core before they
// define anything, so that their classes, functions and pickles are the same to Python whichever of them
// rigidfem/_load_core.py loaded; `build` says which.
#include "bindings.hpp"

PYBIND11_MODULE(RIGIDFEM_MODULE, m) {
  m.attr("__name__") = "rigidfem._core";
  m.attr("build") = RIGIDFEM_BUILD;
  rigidfem::bindings::bind_module(m);
}

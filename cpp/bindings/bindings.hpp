// Shared declarations of the binding files (module rigidfem._core).
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace rigidfem::bindings {
namespace py = pybind11;
void bind_transforms(py::module_& m);
void bind_model(py::module_& m);
void bind_dynamics(py::module_& m);
void bind_profiles(py::module_& m);
void bind_integrators(py::module_& m);
}  // namespace rigidfem::bindings

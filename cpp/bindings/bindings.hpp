// Shared declarations of the binding files (module rigidfem._core).
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>

#include "rigidfem/errors.hpp"
#include "rigidfem/transforms.hpp"

namespace rigidfem::bindings {
namespace py = pybind11;

// Arguments taken as py::object and converted here, so that a wrong type is a ValueError naming
// the argument ("r: expected ..., got 'x'") rather than pybind11's TypeError listing signatures.

/// repr(x), cut to 80 characters, for messages.
inline std::string arg_repr(const py::handle& x) {
  std::string s = py::repr(x);
  return s.size() > 80 ? s.substr(0, 77) + "..." : s;
}

/// A real number (Python int or float, a numpy real scalar or 0-d array, or another number with
/// __float__ such as Fraction and Decimal); not a bool, complex number, string, None or sequence.
/// NaN and inf pass (the caller checks what it needs).
inline double real_arg(const py::handle& x, const std::string& name, const std::string& expected) {
  PyObject* o = x.ptr();
  if (PyFloat_Check(o)) return PyFloat_AS_DOUBLE(o);
  bool ok = !PyBool_Check(o) && !PyComplex_Check(o) && !PyUnicode_Check(o) && !PyBytes_Check(o) && !x.is_none();
  if (ok && !PyLong_Check(o) && py::hasattr(x, "dtype")) {  // numpy scalars and 0-d arrays of real numbers
    ok = py::hasattr(x, "ndim") && x.attr("ndim").cast<int>() == 0;
    if (ok) {
      const std::string kind = py::str(x.attr("dtype").attr("kind"));
      ok = kind == "f" || kind == "i" || kind == "u";
    }
  }
  if (ok) {
    const double v = PyFloat_AsDouble(o);
    if (!(v == -1.0 && PyErr_Occurred())) return v;
    PyErr_Clear();  // an int beyond the range of doubles
  }
  bad(name, expected, arg_repr(x));
}

/// An integer (Python int, numpy integer); not a bool, float or string; within [lo, hi].
inline long long int_arg(const py::handle& x, const std::string& name, const std::string& expected,
                         long long lo = -(1LL << 31), long long hi = (1LL << 31) - 1) {
  PyObject* o = x.ptr();
  if (!PyBool_Check(o) && (PyLong_Check(o) || (py::hasattr(x, "dtype") && PyIndex_Check(o)))) {
    int overflow = 0;
    py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(o));
    if (index) {
      const long long v = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
      if (!overflow && !(v == -1 && PyErr_Occurred()) && v >= lo && v <= hi) return v;
    }
    PyErr_Clear();
  }
  bad(name, expected, arg_repr(x));
}

/// A fixed-size Eigen matrix or vector of real numbers (a numpy array or nested sequence of the
/// shape; complex numbers, strings and None are refused rather than converted).
template <class M>
M matrix_arg(const py::handle& x, const std::string& name, const std::string& expected) {
  PyObject* o = x.ptr();
  if (!x.is_none() && !PyUnicode_Check(o) && !PyBytes_Check(o)) {
    const py::array a = py::array::ensure(x);
    const char kind = a ? a.dtype().kind() : 'x';
    if (kind == 'f' || kind == 'i' || kind == 'u' || kind == 'b') {
      try {
        return py::cast<M>(a);
      } catch (const py::cast_error&) {  // another shape
        bad(name, expected, "shape (" + [&a] {
          std::string s;
          for (py::ssize_t k = 0; k < a.ndim(); ++k) s += (k ? ", " : "") + std::to_string(a.shape(k));
          return s + (a.ndim() == 1 ? ",)" : ")");
        }());
      }
    }
    if (kind == 'c') bad(name, expected + " (real numbers)", "complex values");
  }
  bad(name, expected, arg_repr(x));
}

/// A 1-D array of real numbers (a numpy array or sequence; complex numbers, strings, None and 2-D
/// arrays such as (1, n) are refused rather than converted or flattened).
inline VecX vector_arg(const py::handle& x, const std::string& name, const std::string& expected) {
  PyObject* o = x.ptr();
  if (!x.is_none() && !PyUnicode_Check(o) && !PyBytes_Check(o)) {
    const py::array a = py::array::ensure(x);
    const char kind = a ? a.dtype().kind() : 'x';
    if (kind == 'c') bad(name, expected + " (real numbers)", "complex values");
    if ((kind == 'f' || kind == 'i' || kind == 'u' || kind == 'b') && a.ndim() != 1)
      bad(name, expected, "an array of " + std::to_string(a.ndim()) + " dimensions");
    if (kind == 'f' || kind == 'i' || kind == 'u' || kind == 'b') return py::cast<VecX>(a);
  }
  bad(name, expected, arg_repr(x));
}

/// An array of real numbers of any shape (a numpy array, a nested sequence or a scalar) as float64:
/// booleans and integers converted, complex numbers, strings, None and objects that are not numbers
/// (ragged sequences, Python ints beyond the doubles) refused. Values are not looked at.
inline py::array_t<double> real_array_arg(const py::handle& x, const std::string& name, const std::string& expected) {
  PyObject* o = x.ptr();
  if (!x.is_none() && !PyUnicode_Check(o) && !PyBytes_Check(o)) {
    py::array a;
    try {
      a = py::array::ensure(x);
    } catch (const py::error_already_set&) {  // a sequence numpy cannot take (raising __len__, ...)
    }
    if (!a) PyErr_Clear();
    const char kind = a ? a.dtype().kind() : 'x';
    if (kind == 'c') bad(name, expected + " (real numbers)", "complex values " + arg_repr(x));
    if (kind == 'f' || kind == 'i' || kind == 'u' || kind == 'b' || kind == 'O') {
      auto f = py::array_t<double, py::array::forcecast>::ensure(a);  // objects: each must be a real number
      if (f && (kind != 'O' || [&a] {
            for (const py::handle item : a.attr("ravel")()) {
              PyObject* p = item.ptr();
              if (PyBool_Check(p) || PyComplex_Check(p) || PyUnicode_Check(p) || PyBytes_Check(p) || item.is_none())
                return false;
            }
            return true;
          }()))
        return f;
      PyErr_Clear();
    }
  }
  bad(name, expected, arg_repr(x));
}

/// A list of strings (names), each refused with the argument's name if it is not a string.
inline std::vector<std::string> names_arg(const py::handle& x, const std::string& name, const std::string& expected) {
  if (PyUnicode_Check(x.ptr()) || !py::isinstance<py::sequence>(x)) bad(name, expected, arg_repr(x));
  std::vector<std::string> out;
  for (const py::handle item : py::reinterpret_borrow<py::sequence>(x)) {
    if (!PyUnicode_Check(item.ptr())) bad(name, expected, arg_repr(x));
    out.push_back(item.cast<std::string>());
  }
  return out;
}

void bind_arguments(py::module_& m);
void bind_transforms(py::module_& m);
void bind_model(py::module_& m);
void bind_dynamics(py::module_& m);
void bind_profiles(py::module_& m);
void bind_integrators(py::module_& m);
}  // namespace rigidfem::bindings

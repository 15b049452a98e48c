// Shared declarations of the binding files (module rigidfem._core).
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>

#include "rigidfem/errors.hpp"
#include "rigidfem/model.hpp"
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

// The arguments of a state, each a type that knows its role's name and converts by the rules above, so that a
// binding reads `[](const System& s, Time t, Coordinates q, Rates qd)` and a wrong type or shape is a ValueError
// naming the argument ("q: expected a 1-D array of coordinates (m, rad), got 'x'"); the sizes and values are the
// core's to judge (check_vector: "q: expected 2 (nq) values, got 3"). An array that is already 1-D float64 and
// contiguous is taken as it is (no copy).

/// A time t (s): a real number, finite.
struct Time {
  double value = 0.0;
  operator double() const { return value; }  // NOLINT: the time itself
};

/// A vector of real numbers in a role (q, q̇, q̈, y): the float64 array it was given or converted to.
struct VectorArgument {
  py::array_t<double> array;
  operator Eigen::Ref<const VecX>() const {  // NOLINT: the values themselves, without a copy
    return Eigen::Map<const VecX>(array.data(), array.size());
  }
  VecX vector() const { return Eigen::Map<const VecX>(array.data(), array.size()); }
  /// The largest |x| (for the message of an overflow), 0 for none.
  double largest() const { return array.size() ? Eigen::Map<const VecX>(array.data(), array.size()).cwiseAbs().maxCoeff() : 0.0; }
};
struct Coordinates : VectorArgument {
  static constexpr const char* name = "q";
  static constexpr const char* expected = "a 1-D array of coordinates (m, rad)";
};
struct Rates : VectorArgument {
  static constexpr const char* name = "qd";
  static constexpr const char* expected = "a 1-D array of rates (m/s, rad/s)";
};
struct Accelerations : VectorArgument {
  static constexpr const char* name = "qdd";
  static constexpr const char* expected = "a 1-D array of accelerations (m/s², rad/s²)";
};
struct States : VectorArgument {
  static constexpr const char* name = "y";
  static constexpr const char* expected = "a 1-D array of 2 nq values [q, qd]";
};

/// x as a VectorArgument of role T (ValueError naming T::name otherwise).
template <class T>
T vector_argument(const py::handle& x) {
  T v;
  PyObject* o = x.ptr();
  if (py::isinstance<py::array_t<double>>(x) && py::reinterpret_borrow<py::array>(x).ndim() == 1 &&
      (py::reinterpret_borrow<py::array>(x).flags() & py::array::c_style) && !PyBool_Check(o)) {
    v.array = py::reinterpret_borrow<py::array_t<double>>(x);  // the fast path: taken as it is
    return v;
  }
  auto a = real_array_arg(x, T::name, T::expected);
  if (a.ndim() != 1) {
    std::string shape;
    for (py::ssize_t k = 0; k < a.ndim(); ++k) shape += (k ? ", " : "") + std::to_string(a.shape(k));
    bad(T::name, T::expected, "shape (" + shape + (a.ndim() == 1 ? ",)" : ")"));
  }
  v.array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  return v;
}

/// The load factor λ of statics: a real number, finite.
struct LoadFactor {
  double value = 1.0;
  operator double() const { return value; }  // NOLINT: the factor itself
};
/// static=: True or False.
struct StaticFlag {
  bool value = false;
  operator bool() const { return value; }  // NOLINT: the flag itself
};
/// A material point of the system: a Point, or a Body (its origin).
struct PointArgument {
  Point value;
  operator const Point&() const { return value; }  // NOLINT: the point itself
};
/// Points of the system, each a Point or a Body.
struct PointsArgument {
  std::vector<Point> value;
  operator const std::vector<Point>&() const { return value; }  // NOLINT: the points themselves
};
/// A body of the system: a Body or its index.
struct BodyArgument {
  int value = -1;
  operator int() const { return value; }  // NOLINT: the index itself
};

/// True or False (a numpy bool too), named `name`.
inline bool flag_arg(const py::handle& x, const char* name) {
  if (PyBool_Check(x.ptr())) return x.ptr() == Py_True;
  if (py::hasattr(x, "dtype") && py::str(x.attr("dtype")).cast<std::string>() == "bool" &&
      py::hasattr(x, "ndim") && x.attr("ndim").cast<int>() == 0)
    return x.cast<bool>();
  bad(name, "True or False", arg_repr(x));
}

void bind_arguments(py::module_& m);
void bind_transforms(py::module_& m);
void bind_model(py::module_& m);
void bind_dynamics(py::module_& m);
void bind_profiles(py::module_& m);
void bind_integrators(py::module_& m);
/// Everything of the module rigidfem._core (module_init.cpp's entry point calls it).
void bind_module(py::module_& m);
}  // namespace rigidfem::bindings

namespace pybind11::detail {

// The casters of the roles: a wrong argument is the ValueError naming it, not pybind11's TypeError listing signatures.
template <>
struct type_caster<rigidfem::bindings::Time> {
  PYBIND11_TYPE_CASTER(rigidfem::bindings::Time, const_name("float"));
  bool load(handle src, bool) {
    value.value = rigidfem::bindings::real_arg(src, "t", "a finite time in s");
    if (!std::isfinite(value.value)) rigidfem::bad("t", "a finite time in s", rigidfem::num(value.value));
    return true;
  }
  static handle cast(const rigidfem::bindings::Time& t, return_value_policy, handle) { return PyFloat_FromDouble(t.value); }
};

template <>
struct type_caster<rigidfem::bindings::LoadFactor> {
  PYBIND11_TYPE_CASTER(rigidfem::bindings::LoadFactor, const_name("float"));
  bool load(handle src, bool) {
    value.value = rigidfem::bindings::real_arg(src, "load_factor", "a finite number");
    if (!std::isfinite(value.value)) rigidfem::bad("load_factor", "a finite number", rigidfem::num(value.value));
    return true;
  }
  static handle cast(const rigidfem::bindings::LoadFactor& x, return_value_policy, handle) {
    return PyFloat_FromDouble(x.value);
  }
};

template <>
struct type_caster<rigidfem::bindings::StaticFlag> {
  PYBIND11_TYPE_CASTER(rigidfem::bindings::StaticFlag, const_name("bool"));
  bool load(handle src, bool) {
    value.value = rigidfem::bindings::flag_arg(src, "static");
    return true;
  }
  static handle cast(const rigidfem::bindings::StaticFlag& x, return_value_policy, handle) {
    return handle(x.value ? Py_True : Py_False).inc_ref();
  }
};

template <>
struct type_caster<rigidfem::bindings::PointArgument> {
  PYBIND11_TYPE_CASTER(rigidfem::bindings::PointArgument, const_name("Point"));
  bool load(handle src, bool) {
    if (isinstance<rigidfem::Point>(src))
      value.value = src.cast<rigidfem::Point>();
    else if (isinstance<rigidfem::Body>(src))
      value.value = rigidfem::Point(src.cast<rigidfem::Body>());
    else
      rigidfem::bad("point", "a Point or Body of this system", rigidfem::bindings::arg_repr(src));
    return true;
  }
  static handle cast(const rigidfem::bindings::PointArgument& x, return_value_policy p, handle parent) {
    return type_caster_base<rigidfem::Point>::cast(x.value, p, parent);
  }
};

template <>
struct type_caster<rigidfem::bindings::PointsArgument> {
  PYBIND11_TYPE_CASTER(rigidfem::bindings::PointsArgument, const_name("list[Point]"));
  bool load(handle src, bool) {
    if (!isinstance<sequence>(src) || isinstance<str>(src))
      rigidfem::bad("points", "a list of Points of this system", rigidfem::bindings::arg_repr(src));
    for (const handle p : reinterpret_borrow<sequence>(src)) {
      if (isinstance<rigidfem::Point>(p))
        value.value.push_back(p.cast<rigidfem::Point>());
      else if (isinstance<rigidfem::Body>(p))
        value.value.emplace_back(p.cast<rigidfem::Body>());
      else
        rigidfem::bad("points", "a list of Points of this system", rigidfem::bindings::arg_repr(src));
    }
    return true;
  }
  static handle cast(const rigidfem::bindings::PointsArgument&, return_value_policy, handle) { return none().release(); }
};

template <>
struct type_caster<rigidfem::bindings::BodyArgument> {
  PYBIND11_TYPE_CASTER(rigidfem::bindings::BodyArgument, const_name("Body | int"));
  bool load(handle src, bool) {
    value.value = isinstance<rigidfem::Body>(src)
                      ? src.cast<rigidfem::Body>().index
                      : static_cast<int>(rigidfem::bindings::int_arg(src, "body", "a Body of this system or its index"));
    return true;
  }
  static handle cast(const rigidfem::bindings::BodyArgument& x, return_value_policy, handle) {
    return PyLong_FromLong(x.value);
  }
};

template <class T>
struct vector_role_caster {
  PYBIND11_TYPE_CASTER(T, const_name("numpy.typing.ArrayLike"));
  bool load(handle src, bool) {
    value = rigidfem::bindings::vector_argument<T>(src);
    return true;
  }
  static handle cast(const T& v, return_value_policy, handle) { return v.array.inc_ref(); }
};
template <>
struct type_caster<rigidfem::bindings::Coordinates> : vector_role_caster<rigidfem::bindings::Coordinates> {};
template <>
struct type_caster<rigidfem::bindings::Rates> : vector_role_caster<rigidfem::bindings::Rates> {};
template <>
struct type_caster<rigidfem::bindings::Accelerations> : vector_role_caster<rigidfem::bindings::Accelerations> {};
template <>
struct type_caster<rigidfem::bindings::States> : vector_role_caster<rigidfem::bindings::States> {};

}  // namespace pybind11::detail

// rigidfem._core: the C++ core. Errors: std::invalid_argument -> ValueError,
// rigidfem::SimulationError -> rigidfem.SimulationError (a RuntimeError).
#include <cmath>
#include <optional>

#include "bindings.hpp"
#include "rigidfem/dense_lu.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/model.hpp"
#include "rigidfem/profiles.hpp"
#include "rigidfem/timing.hpp"
#include "rigidfem/joint_motion.hpp"

namespace rigidfem::bindings {

/// The argument conversions of bindings.hpp for the Python layer (rigidfem.base._checks, rigidfem._contract):
/// one rule for what counts as a real number, an integer or an array of reals, wherever it is checked.
void bind_arguments(py::module_& m) {
  m.def(
      "_real", [](const py::object& x, const std::string& name, const std::string& expected) {
        return real_arg(x, name, expected);
      },
      py::arg("x"), py::arg("name"), py::arg("expected"),
      "x as a float: a real number (int, float, numpy real scalar or 0-d array), else ValueError\n"
      "'<name>: expected <expected>, got <repr>'. NaN and inf pass.");
  m.def(
      "_integer",
      [](const py::object& x, const std::string& name, const std::string& expected, long long lo, long long hi) {
        return int_arg(x, name, expected, lo, hi);
      },
      py::arg("x"), py::arg("name"), py::arg("expected"), py::arg("lo"), py::arg("hi"),
      "x as an int in [lo, hi]: a Python or numpy integer (not a bool or float), else the ValueError.");
  m.def("_real_array", &real_array_arg, py::arg("x"), py::arg("name"), py::arg("expected"),
        "x as a float64 array of any shape (bindings.hpp's real_array_arg), else the ValueError.");
}

void bind_transforms(py::module_& m) {
  // Arguments as py::object: a wrong type is a ValueError naming it (NaN in, NaN out is fine here).
  const auto angle = [](const py::object& x, const char* name) { return real_arg(x, name, "an angle in rad"); };
  m.def("R1", [angle](const py::object& phi1) { return R1(angle(phi1, "phi1")); }, py::arg("phi1"),
        "Rotation matrix about x by phi1 (rad), (3, 3).\n"
        "\n"
        "Examples\n"
        "--------\n"
        ">>> import rigidfem as rf\n"
        ">>> rf.R1(0.5).round(3)\n"
        "array([[ 1.   ,  0.   ,  0.   ],\n"
        "       [ 0.   ,  0.878, -0.479],\n"
        "       [ 0.   ,  0.479,  0.878]])");
  m.def("R2", [angle](const py::object& phi2) { return R2(angle(phi2, "phi2")); }, py::arg("phi2"),
        "Rotation matrix about y by phi2 (rad), (3, 3).\n"
        "\n"
        "Examples\n"
        "--------\n"
        ">>> import rigidfem as rf\n"
        ">>> rf.R2(0.5).round(3)\n"
        "array([[ 0.878,  0.   ,  0.479],\n"
        "       [ 0.   ,  1.   ,  0.   ],\n"
        "       [-0.479,  0.   ,  0.878]])");
  m.def("R3", [angle](const py::object& phi3) { return R3(angle(phi3, "phi3")); }, py::arg("phi3"),
        "Rotation matrix about z by phi3 (rad), (3, 3).\n"
        "\n"
        "Examples\n"
        "--------\n"
        ">>> import rigidfem as rf\n"
        ">>> rf.R3(0.5).round(3)\n"
        "array([[ 0.878, -0.479,  0.   ],\n"
        "       [ 0.479,  0.878,  0.   ],\n"
        "       [ 0.   ,  0.   ,  1.   ]])");
  m.def(
      "euler_zyx",
      [angle](const py::object& phi3, const py::object& phi2, const py::object& phi1) {
        return euler_zyx(angle(phi3, "phi3"), angle(phi2, "phi2"), angle(phi1, "phi1"));
      },
      py::arg("phi3"), py::arg("phi2"), py::arg("phi1"),
      "R3(phi3) R2(phi2) R1(phi1), book eq. (2.7): yaw, pitch, roll in rad. (3, 3).\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import numpy as np, rigidfem as rf\n"
      ">>> R = rf.euler_zyx(0.1, 0.2, 0.3)\n"
      ">>> bool(np.allclose(R, rf.R3(0.1) @ rf.R2(0.2) @ rf.R1(0.3)))\n"
      "True");
  m.def(
      "skew", [](const py::object& w) { return skew(matrix_arg<Vec3>(w, "w", "a vector (3,)")); }, py::arg("w"),
      "Skew-symmetric S(w) with S(w) x = w x x. (3, 3).\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import rigidfem as rf\n"
      ">>> rf.skew([1.0, 2.0, 3.0])\n"
      "array([[ 0., -3.,  2.],\n"
      "       [ 3.,  0., -1.],\n"
      "       [-2.,  1.,  0.]])\n"
      ">>> rf.skew([1.0, 2.0, 3.0]) @ [4.0, 5.0, 6.0]\n"
      "array([-3.,  6., -3.])");
  m.def(
      "homogeneous",
      [](const py::object& R, const py::object& r) {
        return homogeneous(matrix_arg<Mat3>(R, "R", "a rotation matrix (3, 3)"),
                           matrix_arg<Vec3>(r, "r", "a translation (3,) in m"));
      },
      py::arg("R"), py::arg("r"),
      "[[R, r], [0, 1]] (4, 4); r in m.\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import numpy as np, rigidfem as rf\n"
      ">>> rf.homogeneous(np.eye(3), [1.0, 2.0, 3.0])\n"
      "array([[1., 0., 0., 1.],\n"
      "       [0., 1., 0., 2.],\n"
      "       [0., 0., 1., 3.],\n"
      "       [0., 0., 0., 1.]])");
  m.def(
      "inverse", [](const py::object& T) { return inverse(matrix_arg<Mat4>(T, "T", "a homogeneous transform (4, 4)")); },
      py::arg("T"),
      "Inverse of a homogeneous transform, [[R^T, -R^T r], [0, 1]] (4, 4).\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import numpy as np, rigidfem as rf\n"
      ">>> T = rf.homogeneous(rf.R3(0.3), [1.0, 0.0, 0.0])\n"
      ">>> bool(np.allclose(rf.inverse(T) @ T, np.eye(4)))\n"
      "True\n"
      ">>> rf.inverse(rf.homogeneous(np.eye(3), [1.0, 2.0, 3.0]))[:3, 3]\n"
      "array([-1., -2., -3.])");

  // (coordinates, q) checked: names from x, y, z, rz, ry, rx; q a real vector of their number.
  auto axes_of = [](const py::object& coordinates) {
    std::vector<Axis> axes;
    for (const auto& n : names_arg(coordinates, "coordinates", "a list of names from 'x', 'y', 'z', 'rz', 'ry', 'rx'"))
      axes.push_back(parse_coordinate(n, "coordinates"));
    return Joint::make("custom", axes).axes;
  };
  auto values_of = [](const py::object& q, std::size_t n) {
    const VecX v = vector_arg(q, "q", std::to_string(n) + " coordinates (m, rad), one per name");
    check_vector(v, static_cast<Eigen::Index>(n), "q", "one per coordinate name");
    return v;
  };
  m.def(
      "joint_transform",
      [axes_of, values_of](const py::object& c, const py::object& q) {
        const auto axes = axes_of(c);
        return joint_transform(axes, values_of(q, axes.size()));
      },
      py::arg("coordinates"), py::arg("q"),
      "Joint transform Trans(x, y, z) R3(phi3) R2(phi2) R1(phi1) restricted to `coordinates`\n"
      "(names from 'x', 'y', 'z', 'rz', 'ry', 'rx', taken in the book's order); q in m and rad. (4, 4).\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import rigidfem as rf\n"
      ">>> rf.joint_transform([\"x\", \"rz\"], [0.5, 0.0])\n"
      "array([[1. , 0. , 0. , 0.5],\n"
      "       [0. , 1. , 0. , 0. ],\n"
      "       [0. , 0. , 1. , 0. ],\n"
      "       [0. , 0. , 0. , 1. ]])");
  m.def(
      "joint_transform_derivative",
      [axes_of, values_of](const py::object& c, const py::object& q, const py::object& i) {
        const auto axes = axes_of(c);
        return joint_transform_derivative(axes, values_of(q, axes.size()),
                                          static_cast<int>(int_arg(i, "i", "the index of a coordinate")));
      },
      py::arg("coordinates"), py::arg("q"), py::arg("i"),
      "dT/dq_i of joint_transform (4, 4).\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import rigidfem as rf\n"
      ">>> rf.joint_transform_derivative([\"x\", \"rz\"], [0.5, 0.0], 0)\n"
      "array([[0., 0., 0., 1.],\n"
      "       [0., 0., 0., 0.],\n"
      "       [0., 0., 0., 0.],\n"
      "       [0., 0., 0., 0.]])");
  m.def(
      "joint_transform_second_derivative",
      [axes_of, values_of](const py::object& c, const py::object& q, const py::object& i, const py::object& j) {
        const auto axes = axes_of(c);
        return joint_transform_second_derivative(axes, values_of(q, axes.size()),
                                                 static_cast<int>(int_arg(i, "i", "the index of a coordinate")),
                                                 static_cast<int>(int_arg(j, "j", "the index of a coordinate")));
      },
      py::arg("coordinates"), py::arg("q"), py::arg("i"), py::arg("j"),
      "d2T/dq_i dq_j of joint_transform (4, 4).\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import rigidfem as rf\n"
      ">>> rf.joint_transform_second_derivative([\"x\", \"rz\"], [0.5, 0.0], 1, 1).round(3)\n"
      "array([[-1.,  0.,  0.,  0.],\n"
      "       [ 0., -1.,  0.,  0.],\n"
      "       [ 0.,  0.,  0.,  0.],\n"
      "       [ 0.,  0.,  0.,  0.]])");
}

namespace {

// The kind of profile whose maker is `maker`; ValueError listing them otherwise.
const ProfileKind& profile_kind(const std::string& maker) {
  std::string names;
  for (const ProfileKind& k : profile_kinds()) {
    if (maker == k.maker) return k;
    names += std::string(names.empty() ? "" : ", ") + k.maker;
  }
  bad("maker", "a kind of profile (" + names + ")", "'" + maker + "'");
}

// A Python value as a profile maker's argument of its type (ValueError naming the argument otherwise).
ProfileValue profile_value(const ProfileArgument& a, const py::handle& x) {
  switch (a.type) {
    case ProfileArgument::Number: return real_arg(x, a.name, a.expected);
    case ProfileArgument::Integer: return static_cast<int>(int_arg(x, a.name, a.expected));
    case ProfileArgument::Numbers: {
      const VecX v = vector_arg(x, a.name, a.expected);
      return std::vector<double>(v.data(), v.data() + v.size());
    }
    case ProfileArgument::Name:
      if (!PyUnicode_Check(x.ptr())) bad(a.name, a.expected, arg_repr(x));
      return x.cast<std::string>();
    case ProfileArgument::Part:
      if (!py::isinstance<Profile>(x)) bad(a.name, a.expected, arg_repr(x));
      return x.cast<ProfilePtr>();
    case ProfileArgument::Parts: {
      if (py::isinstance<Profile>(x) || PyUnicode_Check(x.ptr()) || !py::isinstance<py::sequence>(x))
        bad(a.name, a.expected, arg_repr(x));
      std::vector<ProfilePtr> parts;
      for (const py::handle p : py::reinterpret_borrow<py::sequence>(x)) {
        if (!py::isinstance<Profile>(p)) bad(a.name, a.expected, arg_repr(x));
        parts.push_back(p.cast<ProfilePtr>());
      }
      return parts;
    }
  }
  bad(a.name, a.expected, arg_repr(x));
}

}  // namespace

void bind_profiles(py::module_& m) {
  py::class_<Profile, ProfilePtr> profile(m, "Profile",
      "A prescribed motion q(t) with its rates (see rigidfem.motion).\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import rigidfem as rf\n"
      ">>> p = rf.motion.ramp(2.0, 0.0, 1.0)\n"
      ">>> [round(x, 6) for x in p(0.5)]\n"
      "[0.148679, 1.0, 4.0]\n"
      ">>> p.sample([0.0, 1.0]).round(3)\n"
      "array([[0., 0., 0.],\n"
      "       [1., 2., 0.]])",
                                          py::dynamic_attr());
  profile
      .def(
          "__call__",
          [](const Profile& p, const py::object& time) {
            const double t = real_arg(time, "t", "a finite time in s");
            if (!std::isfinite(t)) bad("t", "a finite time in s", num(t));
            const MotionState s = p.at(t);
            if (!(std::isfinite(s.q) && std::isfinite(s.qd) && std::isfinite(s.qdd)))
              throw SimulationError(t, "the profile " + p.describe() + " is not finite: (q, qd, qdd) = (" + num(s.q) +
                                           ", " + num(s.qd) + ", " + num(s.qdd) + ") (it overflows at this time)");
            return py::make_tuple(s.q, s.qd, s.qdd);
          },
          py::arg("t"), "(q, qd, qdd) at time t (s).")
      .def(
          "sample",
          [](const Profile& p, const Eigen::Ref<const VecX>& times) {
            MatX out(times.size(), 3);
            for (Eigen::Index k = 0; k < times.size(); ++k) {
              if (!std::isfinite(times(k))) bad("times", "finite times in s", num(times(k)));
              const MotionState s = p.at(times(k));
              out.row(k) << s.q, s.qd, s.qdd;
            }
            return out;
          },
          py::arg("times"), "(q, qd, qdd) at each of the times (s): an array (len(times), 3), one call for many.")
      .def("__repr__", [](const Profile& p) { return "<rigidfem motion " + p.describe() + ">"; })
      .def(
          "__reduce__",
          [](const py::object& self) -> py::tuple {
            // Pickled as its maker and the maker's arguments (or, for rigidfem.motion.function, the
            // Python function it keeps as `function`), so that it unpickles bit for bit.
            const ProfileRecipe r = self.cast<const Profile&>().recipe();
            if (r.maker.empty()) {
              if (py::hasattr(self, "function"))
                return py::make_tuple(py::module_::import("rigidfem.model.motion").attr("function"),
                                      py::make_tuple(self.attr("function")));
              throw py::type_error("cannot pickle the profile " + self.cast<const Profile&>().describe() +
                                   ": it is internal to a model (pickle the Model instead)");
            }
            py::tuple arguments(r.arguments.size());
            for (size_t k = 0; k < r.arguments.size(); ++k)
              arguments[k] = std::visit([](const auto& a) { return py::cast(a); }, r.arguments[k]);
            py::tuple maker_and_arguments(r.arguments.size() + 1);
            maker_and_arguments[0] = r.maker;
            for (size_t k = 0; k < r.arguments.size(); ++k) maker_and_arguments[k + 1] = arguments[k];
            return py::make_tuple(py::module_::import("rigidfem._core").attr("_make_profile"), maker_and_arguments);
          });
  // Composition, each a C++ profile holding its parts: p ± r, p ± c, c ± p, c·p, p/c, −p (c a number; anything
  // else: NotImplemented, Python's TypeError) and p.shifted(delay). The result's Python object keeps its parts'
  // (`_parts`), so that a part made by rigidfem.motion.function still pickles as its function.
  auto composed = [](ProfilePtr made, py::tuple parts) {
    py::object o = py::cast(std::move(made));
    o.attr("_parts") = std::move(parts);
    return o;
  };
  // A real number (a Python or NumPy scalar), or nothing: a profile, a string, an array (even of one value)
  // or anything without __float__ makes the operator return NotImplemented (Python's TypeError).
  auto number = [](const py::object& x) -> std::optional<double> {
    if (py::isinstance<Profile>(x) || py::isinstance<py::str>(x) || py::isinstance<py::bytes>(x) ||
        !(PyFloat_Check(x.ptr()) || PyLong_Check(x.ptr()) || PyObject_HasAttrString(x.ptr(), "__float__")))
      return std::nullopt;
    if (py::hasattr(x, "ndim") && x.attr("ndim").cast<int>() != 0) return std::nullopt;
    try {
      return x.cast<double>();
    } catch (const py::cast_error&) {
      return std::nullopt;
    }
  };
  const auto not_implemented = [] { return py::reinterpret_borrow<py::object>(Py_NotImplemented); };
  // w_self · self + w_other · other, other a profile or a number (then an offset)
  auto combine = [composed, number, not_implemented](const py::object& self, const py::object& other, double w_self,
                                                     double w_other) -> py::object {
    const ProfilePtr p = self.cast<ProfilePtr>();
    if (py::isinstance<Profile>(other))
      return composed(sum_profile({w_self, w_other}, {p, other.cast<ProfilePtr>()}, 0.0), py::make_tuple(self, other));
    const std::optional<double> c = number(other);
    if (!c) return not_implemented();
    if (!std::isfinite(*c)) bad("offset", "a finite number", num(*c));
    return composed(sum_profile({w_self}, {p}, w_other * *c), py::make_tuple(self));
  };
  // c · self, or self / c
  auto scale = [composed, number, not_implemented](const py::object& self, const py::object& factor,
                                                   bool divide) -> py::object {
    const std::optional<double> c = number(factor);
    if (!c) return not_implemented();
    if (!std::isfinite(*c) || (divide && *c == 0.0))
      bad("weights", divide ? "a finite, non-zero divisor" : "a finite number", num(*c));
    return composed(sum_profile({divide ? 1.0 / *c : *c}, {self.cast<ProfilePtr>()}, 0.0), py::make_tuple(self));
  };
  profile.attr("__array_ufunc__") = py::none();  // NumPy arrays do not broadcast over a profile: p * array is a TypeError
  profile
      .def("__add__", [combine](const py::object& p, const py::object& r) { return combine(p, r, 1.0, 1.0); })
      .def("__radd__", [combine](const py::object& p, const py::object& r) { return combine(p, r, 1.0, 1.0); })
      .def("__sub__", [combine](const py::object& p, const py::object& r) { return combine(p, r, 1.0, -1.0); })
      .def("__rsub__", [combine](const py::object& p, const py::object& r) { return combine(p, r, -1.0, 1.0); })
      .def("__mul__", [scale](const py::object& p, const py::object& c) { return scale(p, c, false); })
      .def("__rmul__", [scale](const py::object& p, const py::object& c) { return scale(p, c, false); })
      .def("__truediv__", [scale](const py::object& p, const py::object& c) { return scale(p, c, true); })
      .def("__neg__", [scale](const py::object& p) { return scale(p, py::float_(-1.0), false); })
      .def("__pos__", [](const py::object& p) { return p; })
      .def(
          "shifted",
          [composed](const py::object& p, const py::object& delay) {
            const double d = real_arg(delay, "delay", "a finite time in s");
            return composed(shifted_profile(p.cast<ProfilePtr>(), d), py::make_tuple(p));
          },
          py::arg("delay"), "The same motion `delay` s later: q(t − delay), with its rates.");
  // Every kind of profile through its row of profile_kinds(): the arguments converted by their types (ValueError
  // naming one of the wrong type), judged by the maker (naming the first bad one); a part's Python object is kept
  // (`_parts`) so that a part made by rigidfem.motion.function still pickles as its function.
  m.def(
      "_make_profile",
      [composed](const std::string& maker, const py::args& args) {
        const ProfileKind& kind = profile_kind(maker);
        if (args.size() != kind.arguments.size())
          bad("arguments", std::to_string(kind.arguments.size()) + " for " + maker,
              std::to_string(args.size()));
        std::vector<ProfileValue> values;
        py::list parts;
        for (std::size_t k = 0; k < args.size(); ++k) {
          values.push_back(profile_value(kind.arguments[k], args[k]));
          if (kind.arguments[k].type == ProfileArgument::Part) parts.append(args[k]);
          if (kind.arguments[k].type == ProfileArgument::Parts)
            for (const py::handle part : args[k]) parts.append(part);
        }
        return composed(kind.make(values), py::tuple(parts));
      },
      py::arg("maker"),
      "The profile of the kind `maker` (a row of _profile_kinds) from its arguments, in the row's order.");
  m.def(
      "_profile_kinds",
      [] {
        static const char* types[] = {"number", "integer", "numbers", "name", "profile", "profiles"};
        py::list kinds;
        for (const ProfileKind& k : profile_kinds()) {
          py::list arguments;
          for (const ProfileArgument& a : k.arguments)
            arguments.append(py::dict(py::arg("name") = a.name, py::arg("type") = types[a.type],
                                      py::arg("expected") = a.expected, py::arg("affine") = a.affine));
          kinds.append(py::dict(py::arg("maker") = k.maker, py::arg("arguments") = arguments));
        }
        return kinds;
      },
      "The kinds of profile, each a dict: maker, arguments (name, type, expected, affine: whether the profile is "
      "affine in its numbers) in the maker's order.");
  m.def("_point_to_point_laws", &point_to_point_laws, "The laws of rest_to_rest_profile and ramp_profile, by name.");
  m.def(
      "callback_profile",
      [](std::function<std::tuple<double, double, double>(double)> f) {
        // pybind11's function wrapper takes the GIL for the call and the conversion.
        return callback_profile([f = std::move(f)](double t) {
          const auto [q, qd, qdd] = f(t);
          return MotionState{q, qd, qdd};
        });
      },
      py::arg("function"));
}

void bind_module(py::module_& m) {
  m.doc() = "rigidfem C++ core: transforms, models, kinematics, the Lagrange and recursive formulations, integrators.";
  static PyObject* simulation_error = nullptr;  // the Python type, for the translator below
  auto& registered = py::register_exception<rigidfem::SimulationError>(m, "SimulationError", PyExc_RuntimeError);
  simulation_error = registered.ptr();
  registered.attr("__doc__") =
      "A numerical failure, a RuntimeError whose message names the time (s) and the cause: a singular mass or "
      "iteration matrix, a step size below the minimum, a NaN or inf state, Newton divergence in a step or a load "
      "step of the statics, max_steps, gimbal lock of ZYX Euler angles. Its `time` (s) and `cause` say when and why.\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import rigidfem as rf\n"
      ">>> issubclass(rf.SimulationError, RuntimeError)\n"
      "True";
  // Every SimulationError carries its time and cause (ForceLawError's own translator, registered later, comes first).
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const rigidfem::SimulationError& e) {
      py::object error = py::reinterpret_borrow<py::object>(simulation_error)(e.what());
      error.attr("time") = e.time;
      error.attr("cause") = e.cause;
      PyErr_SetObject(simulation_error, error.ptr());
    }
  });
  bind_arguments(m);
  bind_transforms(m);
  bind_profiles(m);
  bind_model(m);
  bind_dynamics(m);
  bind_integrators(m);
  auto bench = m.def_submodule("_bench", "Maintainers' timing helpers for benchmarks/ (not public API).");
  bench.def(
      "forward_dynamics_seconds",
      [](const rigidfem::System& s, double t, const Eigen::Ref<const rigidfem::VecX>& q,
         const Eigen::Ref<const rigidfem::VecX>& qd, int calls) {
        py::gil_scoped_release release;
        return rigidfem::forward_dynamics_seconds(s, t, q, qd, calls);
      },
      py::arg("system"), py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("calls"),
      "Seconds per forward-dynamics call, timed in C++ on one workspace after a warm-up call.");
  bench.def(
      "implicit_step_parts_seconds",
      [](const rigidfem::System& s, double t, const rigidfem::VecX& q, const rigidfem::VecX& qd,
         const rigidfem::VecX& qdd, int calls) {
        py::gil_scoped_release release;
        return rigidfem::implicit_step_parts_seconds(s, t, q, qd, qdd, calls);
      },
      py::arg("system"), py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("calls"),
      "Seconds per call of the parts of an implicit step (residual, tangent, LU factor and solve, the O(n)\n"
      "armature factor and solve), timed in C++.");
  bench.def(
      "dense_lu_solutions",
      [](const Eigen::MatrixXcd& S, const Eigen::VectorXcd& b) {
        if (S.rows() != S.cols())
          rigidfem::bad("S", "a square matrix", std::to_string(S.rows()) + " x " + std::to_string(S.cols()));
        if (b.size() != S.rows())
          rigidfem::bad("b", std::to_string(S.rows()) + " values (S's rows)", std::to_string(b.size()));
        rigidfem::DenseLU real;
        rigidfem::ComplexLU complex;
        real.compute(S.real());
        complex.compute(S);
        rigidfem::VecX x, xt;
        Eigen::VectorXcd z, zt;
        real.solve(b.real(), x), real.solve_transposed(b.real(), xt);
        complex.solve(b, z), complex.solve_transposed(b, zt);
        return py::make_tuple(x, xt, z, zt, real.pivots(), complex.pivots());
      },
      py::arg("S"), py::arg("b"),
      "The dense Newton matrices' LU (dense_lu.hpp), for the tests: (x, x_T, z, z_T, u, u_c) with Re S x = Re b,\n"
      "Re Sᵀ x_T = Re b, S z = b, Sᵀ z_T = b and the pivots of Re S and of S.");
}

}  // namespace rigidfem::bindings

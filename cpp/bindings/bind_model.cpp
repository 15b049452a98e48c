// Joint, Body, Point, Load and Model. The friendly keyword API lives in
// rigidfem/model/model.py; these are the primitives it calls.
#include <cmath>
#include <memory>

#include "bindings.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/model.hpp"
#include "rigidfem/system.hpp"

namespace rigidfem::bindings {

namespace {

// rigidfem._core.ForceLawError: a ValueError and a SimulationError (see ForceLawError in model.hpp).
PyObject* force_law_error = nullptr;

Vec3 finite_offset(const Vec3& r) {
  if (!r.allFinite()) bad("r", "a finite offset (3,) in m in the body frame", "NaN or inf");
  return r;
}

std::string short_repr(const py::handle& x) {
  std::string s = py::repr(x);
  return s.size() > 80 ? s.substr(0, 77) + "..." : s;
}

// The value of what a force law returned if it is one finite number (a Python or numpy real
// scalar, or anything else float() takes), else false with `got` describing it.
bool force_value(const py::object& r, double& value, std::string& got) {
  PyObject* o = r.ptr();
  if (PyFloat_CheckExact(o)) {
    value = PyFloat_AS_DOUBLE(o);
  } else {
    if (r.is_none() || PyBool_Check(o) || PyUnicode_Check(o) || PyBytes_Check(o)) {
      got = short_repr(r);
      return false;
    }
    if (py::hasattr(r, "dtype") && py::hasattr(r, "ndim")) {  // numpy scalars and arrays
      if (r.attr("ndim").cast<int>() != 0) {
        got = "an array of shape " + std::string(py::str(r.attr("shape")));
        return false;
      }
      const std::string kind = py::str(r.attr("dtype").attr("kind"));
      if (kind != "f" && kind != "i" && kind != "u") {
        got = short_repr(r);
        return false;
      }
    }
    value = PyFloat_AsDouble(o);
    if (value == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();
      got = short_repr(r);
      return false;
    }
  }
  if (!std::isfinite(value)) {
    got = num(value);
    return false;
  }
  return true;
}

// A Python force law Q(t, x, ẋ) as a ForceLaw (called with or without the GIL held) that checks
// what it returns; the law's own exceptions (ZeroDivisionError, KeyboardInterrupt ...) propagate.
// `on` names what it acts on ("coordinate 'hub.rz'"), x and xd its arguments ("q", "qd").
ForceLaw python_law(const py::function& f, const std::string& on, const char* x = "q", const char* xd = "qd",
                    const char* units = "N or N·m") {
  // The reference is dropped under the GIL wherever the last copy of the law dies.
  std::shared_ptr<py::object> law(new py::object(f), [](py::object* o) {
    py::gil_scoped_acquire gil;
    delete o;
  });
  const std::string name = py::hasattr(f, "__qualname__") ? std::string(py::str(f.attr("__qualname__")))
                                                           : short_repr(f);
  const std::string what = "the force law '" + name + "' on " + on;
  return [law, what, x, xd, units](double t, double q, double qd) {
    py::gil_scoped_acquire gil;
    const py::object r = (*law)(t, q, qd);
    double value = 0.0;
    std::string got;
    if (force_value(r, value, got)) return value;
    const std::string state = std::string(x) + " = " + num(q, 10) + ", " + xd + " = " + num(qd, 10);
    const std::string expected = std::string("a finite number (") + units + ")";
    throw ForceLawError(t, what + " returned " + got + " at " + state + "; expected " + expected,
                        "force: expected " + what + " to return " + expected + ", got " + got + " at t = " +
                            num(t, 10) + " s, " + state);
  };
}

// The kind called `kind` among `kinds` (element_law_kinds(), coordinate_law_kinds()); ValueError listing them.
template <class Kinds>
const typename Kinds::value_type& kind_called(const Kinds& kinds, const std::string& kind, const std::string& what) {
  std::string names;
  for (const auto& k : kinds) {
    if (kind == k.info().kind) return k;
    names += std::string(names.empty() ? "" : ", ") + k.info().kind;
  }
  bad("law", what + " (" + names + ")", "'" + kind + "'");
}

const ElementLawKind& element_kind(const std::string& kind) {
  return kind_called(element_law_kinds(), kind, "a law of a force element");
}

const CoordinateLawKind& coordinate_kind(const std::string& kind) {
  return kind_called(coordinate_law_kinds(), kind, "a law of a joint coordinate beyond its own spring-damping law");
}

// The constants' values of a law from a dict {name: number} (the defaults for those not given), each a real
// number by the bindings' rule (ValueError naming it); their bounds are the law's validate().
std::vector<double> law_values(const LawInfo& info, const py::dict& given) {
  std::vector<double> values = defaults(info);
  for (const auto& [key, value] : given) {
    const std::string name = py::str(key);
    const int k = constant_index(info, name);
    values[k] = real_arg(value, name, std::string("a number in ") + info.constants[k].unit);
  }
  return values;
}

// A law's description as a dict (rigidfem.laws reads it).
py::dict law_kind(const LawInfo& info, bool addable) {
  py::list constants;
  for (const Constant& c : info.constants)
    constants.append(py::dict(py::arg("name") = c.name, py::arg("unit") = c.unit,
                              py::arg("rotation_unit") = c.rotation_unit ? c.rotation_unit : c.unit,
                              py::arg("default") = c.value, py::arg("lower") = c.lower,
                              py::arg("positive") = c.positive, py::arg("doc") = c.doc,
                              py::arg("parameter") = c.parameter, py::arg("linear") = c.linear,
                              py::arg("upper") = c.upper));
  auto text = [](const char* s) -> py::object { return s ? py::object(py::str(s)) : py::object(py::none()); };
  return py::dict(py::arg("kind") = info.kind, py::arg("acts_on") = info.acts_on, py::arg("doc") = info.doc,
                  py::arg("constants") = constants, py::arg("profile") = text(info.profile),
                  py::arg("profile_name") = text(info.profile_name), py::arg("profile_units") = text(info.profile_units),
                  py::arg("function") = text(info.function), py::arg("addable") = addable);
}

}  // namespace

void bind_model(py::module_& m) {
  // A ValueError where a System method meets it, and a SimulationError (registered by module.cpp
  // before bind_model) as which a simulation reports it, with its time and cause.
  const py::object bases = py::make_tuple(m.attr("SimulationError"), py::handle(PyExc_ValueError));
  force_law_error = PyErr_NewExceptionWithDoc(
      "rigidfem._core.ForceLawError",
      "A Python force law returned no finite number (None, a string, an array, NaN or inf): a ValueError\n"
      "(and a SimulationError, with `time` and `cause`), raised by System methods; simulate() raises it as\n"
      "the SimulationError at that time.\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import rigidfem as rf\n"
      ">>> issubclass(rf.ForceLawError, rf.SimulationError), issubclass(rf.ForceLawError, ValueError)\n"
      "(True, True)",
      bases.ptr(), nullptr);
  if (force_law_error == nullptr) throw py::error_already_set();
  m.attr("ForceLawError") = py::handle(force_law_error);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ForceLawError& e) {
      py::object error = py::reinterpret_borrow<py::object>(force_law_error)(e.what());
      error.attr("time") = e.time;
      error.attr("cause") = e.cause;
      PyErr_SetObject(force_law_error, error.ptr());
    }
  });

  py::class_<Joint>(m, "JointSpec",
      "Active coordinates of a joint with their springs and dampers.\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import rigidfem as rf\n"
      ">>> spec = rf.Joint.revolute(\"y\", stiffness=5.0, damping=0.1)\n"
      ">>> type(spec).__name__, spec.kind, spec.coordinates\n"
      "('JointSpec', 'revolute', ['ry'])\n"
      ">>> spec.stiffness, spec.damping\n"
      "([5.0], [0.1])")
      .def(py::init([](const std::string& kind, const std::vector<std::string>& coordinates) {
             std::vector<Axis> axes;
             for (const auto& c : coordinates) axes.push_back(parse_coordinate(c, "coordinates"));
             return Joint::make(kind, axes);
           }),
           py::arg("kind"), py::arg("coordinates"))
      .def_readonly("kind", &Joint::kind)
      .def_property_readonly("coordinates",
                             [](const Joint& j) {
                               std::vector<std::string> names;
                               for (Axis a : j.axes) names.push_back(axis_name(a));
                               return names;
                             })
      .def_readwrite("stiffness", &Joint::stiffness)
      .def_readwrite("rest", &Joint::rest)
      .def_readwrite("damping", &Joint::damping)
      .def_readwrite("linear", &Joint::linear, "The book's linear model: T = [[1 + S(phi), r], [0, 1]].")
      .def_property_readonly("ncoords", &Joint::ncoords)
      .def(
          "add_coupling",
          [](Joint& j, const py::object& body, const py::object& slot, const py::object& G) {
            const Mat4 g = matrix_arg<Mat4>(G, "G", "a generator (4, 4)");
            if (!g.allFinite()) bad("G", "a generator (4, 4) of finite values", "NaN or inf");
            j.coupled.push_back({static_cast<int>(int_arg(body, "body", "a body index (int)")),
                                 static_cast<int>(int_arg(slot, "slot", "a coordinate index (int)")), g});
          },
          py::arg("body"), py::arg("slot"), py::arg("G"),
          "Let coordinate `slot` of an earlier body (index) also move this linear joint, with generator G (4, 4)\n"
          "in this joint's frame: T = 1 + sum G q (used by the linear model of beams).")
      .def(py::pickle(
          [](const Joint& j) {
            std::vector<std::string> coordinates;
            for (Axis a : j.axes) coordinates.push_back(axis_name(a));
            py::list coupled;
            for (const auto& c : j.coupled) coupled.append(py::make_tuple(c.body, c.slot, c.G));
            return py::make_tuple(j.kind, coordinates, j.stiffness, j.rest, j.damping, j.linear, coupled);
          },
          [](const py::tuple& s) {
            std::vector<Axis> axes;
            for (const auto& c : s[1].cast<std::vector<std::string>>()) axes.push_back(parse_coordinate(c, "coordinates"));
            Joint j = Joint::make(s[0].cast<std::string>(), axes);
            j.stiffness = s[2].cast<std::vector<double>>();
            j.rest = s[3].cast<std::vector<double>>();
            j.damping = s[4].cast<std::vector<double>>();
            j.linear = s[5].cast<bool>();
            for (const auto& c : s[6].cast<py::list>()) {
              const auto t = c.cast<py::tuple>();
              j.coupled.push_back({t[0].cast<int>(), t[1].cast<int>(), t[2].cast<Mat4>()});
            }
            return j;
          }));

  py::class_<Body>(m, "Body",
      "Handle of a body of a Model (index -1 is the ground).\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import rigidfem as rf\n"
      ">>> model, h = rf.samples.pendulum()\n"
      ">>> system = model.compile()\n"
      ">>> h[\"link\"]\n"
      "<rigidfem Body 'link' #0>\n"
      ">>> h[\"link\"].index, h[\"link\"].name\n"
      "(0, 'link')\n"
      ">>> model.ground.index\n"
      "-1")
      .def(py::init<>(), "The ground.")
      .def(py::init([](int index, const std::string& name, std::uint64_t model) { return Body{index, name, model}; }),
           py::arg("index"), py::arg("name"), py::arg("model") = 0)
      .def_readonly("index", &Body::index)
      .def_readonly("name", &Body::name)
      .def_readonly("model", &Body::model, "Id of the Model that made the handle (0: unknown).")
      .def(
          "point",
          [](const Body& b, const py::object& r) {
            return Point(b.index, finite_offset(matrix_arg<Vec3>(r, "r", "an offset (3,) in m in the body frame")),
                         b.model);
          },
          py::arg("r"), "The material point at r (m, body frame).")
      .def_property_readonly("origin", [](const Body& b) { return Point(b); }, "The point at the body frame's origin.")
      .def("__repr__", [](const Body& b) { return "<rigidfem Body '" + b.name + "' #" + std::to_string(b.index) + ">"; })
      .def(py::pickle([](const Body& b) { return py::make_tuple(b.index, b.name, b.model); },
                      [](const py::tuple& s) {
                        return Body{s[0].cast<int>(), s[1].cast<std::string>(), s[2].cast<std::uint64_t>()};
                      }));

  py::class_<Point>(m, "Point",
      "A material point: body index and position r (m) in the body frame.\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import rigidfem as rf\n"
      ">>> model, h = rf.samples.pendulum()\n"
      ">>> system = model.compile()\n"
      ">>> p = h[\"link\"].point((0.0, 0.0, -1.0))\n"
      ">>> p\n"
      "<rigidfem Point on body #0 at r = (0, 0, -1) m>\n"
      ">>> system.position(p, 0.0, [0.0])\n"
      "array([ 0.,  0., -1.])")
      .def(py::init([](const py::object& body, const py::object& r) {
             return Point(static_cast<int>(int_arg(body, "body", "a body index (int; -1 the ground)")),
                          finite_offset(matrix_arg<Vec3>(r, "r", "an offset (3,) in m in the body frame")));
           }),
           py::arg("body"), py::arg("r"))
      .def(py::init<const Body&>(), py::arg("body"))
      .def_readonly("body", &Point::body)
      .def_readonly("r", &Point::r)
      .def_readonly("model", &Point::model, "Id of the Model whose body the point is on (0: unknown).")
      .def("__repr__", [](const Point& p) {
        return "<rigidfem Point on body #" + std::to_string(p.body) + " at r = (" + num(p.r.x()) + ", " + num(p.r.y()) +
               ", " + num(p.r.z()) + ") m>";
      })
      .def(py::pickle([](const Point& p) { return py::make_tuple(p.body, p.r, p.model); },
                      [](const py::tuple& s) {
                        return Point(s[0].cast<int>(), s[1].cast<Vec3>(), s[2].cast<std::uint64_t>());
                      }));
  py::implicitly_convertible<Body, Point>();

  m.def(
      "pseudo_inertia",
      [](const py::object& mass, const py::object& com, const py::object& inertia) {
        return pseudo_inertia(real_arg(mass, "mass", "a mass in kg"), matrix_arg<Vec3>(com, "com", "a point (3,) in m"),
                              matrix_arg<Mat3>(inertia, "inertia", "an inertia tensor (3, 3) in kg m^2"));
      },
      py::arg("mass"), py::arg("com"), py::arg("inertia"),
        "Pseudo-inertia H = int r r^T dm (4, 4) of a body: mass (kg), centre of mass com (3,) m and\n"
        "inertia tensor (3, 3) about the centre of mass (kg m^2), all in the body frame.\n"
        "\n"
        "Examples\n"
        "--------\n"
        ">>> import numpy as np, rigidfem as rf\n"
        ">>> rf.pseudo_inertia(2.0, [0.5, 0.0, 0.0], np.diag([0.01, 0.02, 0.02])).round(3)\n"
        "array([[0.515, 0.   , 0.   , 1.   ],\n"
        "       [0.   , 0.005, 0.   , 0.   ],\n"
        "       [0.   , 0.   , 0.005, 0.   ],\n"
        "       [1.   , 0.   , 0.   , 2.   ]])");

  py::class_<Model>(m, "_Model")
      .def(py::init<const Vec3&>(), py::arg("gravity"))
      .def("_add_body", &Model::add_body, py::arg("name"), py::arg("parent"), py::arg("joint"), py::arg("placement"),
           py::arg("mass"), py::arg("com"), py::arg("inertia"))
      .def(
          "_add_bodies",
          [](Model& model, const std::vector<std::string>& names, const std::vector<int>& parents, const Joint& joint,
             const Eigen::Ref<const RowMatX>& stiffness, const Eigen::Ref<const RowMatX>& damping,
             const Eigen::Ref<const RowMatX>& placements, const Eigen::Ref<const VecX>& masses,
             const Eigen::Ref<const RowMatX>& coms, const Eigen::Ref<const RowMatX>& inertias) {
            const auto n = static_cast<Eigen::Index>(names.size());
            const Eigen::Index k = joint.ncoords();
            if (static_cast<Eigen::Index>(parents.size()) != n || stiffness.rows() != n || stiffness.cols() != k ||
                damping.rows() != n || damping.cols() != k || placements.rows() != n || placements.cols() != 16 ||
                masses.size() != n || coms.rows() != n || coms.cols() != 3 || inertias.rows() != n ||
                inertias.cols() != 9)
              bad("bodies", "one row per name: parents (n), stiffness and damping (n, ncoords), placements (n, 16), "
                            "masses (n), coms (n, 3), inertias (n, 9)", "other shapes");
            std::vector<BodySpec> specs(n);
            for (Eigen::Index i = 0; i < n; ++i) {
              BodySpec& b = specs[i];
              b.name = names[i];
              b.parent = parents[i];
              b.joint = joint;
              for (Eigen::Index c = 0; c < k; ++c) {
                b.joint.stiffness[c] = stiffness(i, c);
                b.joint.damping[c] = damping(i, c);
              }
              b.placement = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(placements.data() + i * placements.outerStride());
              b.mass = masses(i);
              b.com = coms.row(i).transpose();
              b.inertia = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(inertias.data() + i * inertias.outerStride());
            }
            return model.add_bodies(std::move(specs));
          },
          py::arg("names"), py::arg("parents"), py::arg("joint"), py::arg("stiffness"), py::arg("damping"),
          py::arg("placements"), py::arg("masses"), py::arg("coms"), py::arg("inertias"),
          "Adds bodies in order, each with `joint` but its own row of stiffness and damping; all are checked\n"
          "before any is added. placements and inertias are row-major 4x4 and 3x3 per row.")
      .def("_coordinate_name", &Model::coordinate_name, py::arg("body"), py::arg("coordinate"),
           "'body.axis' of coordinate `coordinate` (-1: the joint's only one) of a body's joint.")
      .def("_truncate", &Model::truncate, py::arg("n"), "Removes the bodies n, n + 1, ... (undo of a failed builder).")
      .def("_prescribe", &Model::prescribe, py::arg("body"), py::arg("coordinate"), py::arg("motion"))
      .def(
          "_add_generalized_force",
          [](Model& model, int body, int coordinate, double value, const py::object& law) {
            if (law.is_none()) return model.add_generalized_force(body, coordinate, value, nullptr);
            if (!PyCallable_Check(law.ptr())) bad("force", "a number or a function Q(t, q, qd)", short_repr(law));
            const std::string name = model.coordinate_name(body, coordinate);  // checks body and coordinate
            model.add_generalized_force(body, coordinate, value, python_law(law, "coordinate '" + name + "'"));
          },
          py::arg("body"), py::arg("coordinate"), py::arg("value"), py::arg("law"))
      .def(
          "_add_maxwell_arms",
          [](Model& model, const std::vector<int>& bodies, const std::vector<int>& coordinates,
             const std::vector<double>& stiffness, const std::vector<double>& tau) {
            const std::size_t n = bodies.size();
            if (coordinates.size() != n || stiffness.size() != n || tau.size() != n)
              bad("arms", "bodies, coordinates, stiffness and tau of one length", "other lengths");
            for (std::size_t k = 0; k < n; ++k) model.add_maxwell_arm(bodies[k], coordinates[k], {stiffness[k], tau[k]});
          },
          py::arg("bodies"), py::arg("coordinates"), py::arg("stiffness"), py::arg("tau"),
          "Adds Maxwell arms (k in N/m or N·m/rad, tau in s) on joint coordinates (-1: the joint's only one).")
      .def(
          "_add_load",
          [](Model& model, int body, const Vec3& point, const Vec3& force, const Vec3& torque, bool follower,
             ProfilePtr scale) { model.add_load({body, point, force, torque, follower, std::move(scale)}); },
          py::arg("body"), py::arg("point"), py::arg("force"), py::arg("torque"), py::arg("follower"),
          py::arg("scale"))
      .def(
          "_add_loop",
          [](Model& model, const std::string& name, const std::string& kind, int a, const Mat4& frame_a, int b,
             const Mat4& frame_b, double length, ProfilePtr drive, bool actuator) {
            const int k = model.add_loop(
                {name, parse_loop_kind(kind, "kind"), a, b, frame_a, frame_b, length, std::move(drive), actuator});
            return model.loops()[k].name;
          },
          py::arg("name"), py::arg("kind"), py::arg("a"), py::arg("frame_a"), py::arg("b"), py::arg("frame_b"),
          py::arg("length"), py::arg("drive"), py::arg("actuator") = false)
      .def_static(
          "_loop_kinds",
          [] {
            // name -> constraint rows of every loop kind, from the one table (constraints.cpp)
            py::dict kinds;
            for (int k = 0; k < loop_kind_count; ++k)
              kinds[loop_kind_name(static_cast<LoopKind>(k))] = loop_rows(static_cast<LoopKind>(k));
            return kinds;
          },
          "The loop kinds and their numbers of constraint rows.")
      .def_static(
          "_loop_kind_table",
          [] {
            py::list kinds;
            for (int k = 0; k < loop_kind_count; ++k) {
              const auto kind = static_cast<LoopKind>(k);
              kinds.append(py::dict(py::arg("kind") = loop_kind_name(kind), py::arg("rows") = loop_rows(kind),
                                    py::arg("free") = loop_kind_doc(kind)));
            }
            return kinds;
          },
          "The loop kinds, each a dict: kind, rows (constraint equations), free (what it leaves free).")
      .def("_wind", &Model::wind, py::arg("element"), py::arg("body"), py::arg("coordinate"), py::arg("radius"),
           py::arg("capstan") = 0.0, py::arg("smoothing") = 0.0,
           "Winds force element `element` (a rope) on coordinate `coordinate` (-1: the only one) of body `body`'s\n"
           "joint, of radius `radius` (m): l_u gains r q, and the coordinate takes r P c, c the capstan's friction\n"
           "exp(-sgn(r) capstan tanh(qd/smoothing)).")
      .def(
          "_add_force_element",
          [](Model& model, const std::string& name, int a, const Vec3& point_a, int b, const Vec3& point_b,
             const std::string& kind, const py::dict& values, ProfilePtr profile, const py::object& function) {
            const ElementLawKind& k = element_kind(kind);
            const AxialFunction f = function.is_none()
                                        ? AxialFunction()
                                        : python_law(function, "force element '" + name + "'", "l", "ld", "N");
            const ForceElement e{name, a, b, point_a, point_b,
                                 k.make(law_values(k.info(), values), std::move(profile), f)};
            return model.force_elements()[model.add_force_element(e)].name;
          },
          py::arg("name"), py::arg("a"), py::arg("point_a"), py::arg("b"), py::arg("point_b"), py::arg("kind"),
          py::arg("values"), py::arg("profile"), py::arg("function"),
          "Adds a force element of the law `kind` (its constants' values by name, the rest their defaults), with its\n"
          "profile and Python function where the kind takes them; returns its name.")
      .def(
          "_add_shape",
          [](Model& model, const std::string& name, int body, const std::string& kind, const Vec3& a, const Vec3& b,
             const Vec3& normal, const Vec3& half_extents, const Mat3& rotation, double radius) {
            Shape shape{name, body, ShapeKind::Sphere, a, b, normal, half_extents, rotation, radius};
            const ShapeKind kinds[] = {ShapeKind::Sphere, ShapeKind::Capsule, ShapeKind::Box, ShapeKind::HalfSpace};
            bool known = false;
            for (const ShapeKind k : kinds)
              if (kind == shape_kind_name(k)) shape.kind = k, known = true;
            if (!known) bad("kind", "'sphere', 'capsule', 'box' or 'half_space'", "'" + kind + "'");
            return model.add_shape(shape);
          },
          py::arg("name"), py::arg("body"), py::arg("kind"), py::arg("a"), py::arg("b"), py::arg("normal"),
          py::arg("half_extents"), py::arg("rotation"), py::arg("radius"),
          "Adds a shape fixed on `body` (-1: the ground; rigidfem/contact.hpp); returns its index.")
      .def(
          "_add_contact",
          [](Model& model, const std::string& name, const std::vector<int>& a, const std::vector<int>& b,
             const std::string& kind, const py::dict& values) {
            const ContactLawKind& k = kind_called(contact_law_kinds(), kind, "a contact law");
            return model.add_contact({name, a, b, k.make(law_values(k.info(), values))});
          },
          py::arg("name"), py::arg("a"), py::arg("b"), py::arg("kind"), py::arg("values"),
          "Adds a contact of the law `kind` between the shapes `a` and `b` (indices); returns its index.")
      .def_property_readonly("_shape_table", [](const Model& model) {
            py::list shapes;
            for (const Shape& s : model.shapes())
              shapes.append(py::dict(py::arg("name") = s.name, py::arg("body") = s.body,
                                     py::arg("kind") = shape_kind_name(s.kind), py::arg("a") = s.a, py::arg("b") = s.b,
                                     py::arg("normal") = s.n, py::arg("half_extents") = s.h,
                                     py::arg("rotation") = s.R, py::arg("radius") = s.radius));
            return shapes;
          }, "The shapes, each a dict: name, body, kind, a, b, normal, half_extents, rotation, radius.")
      .def(
          "_add_coordinate_law",
          [](Model& model, int body, int coordinate, const std::string& kind, const py::dict& values,
             const py::object& function) {
            const CoordinateLawKind& k = coordinate_kind(kind);
            const std::string name = model.coordinate_name(body, coordinate);  // checks body and coordinate
            const ScalarFunction f = function.is_none() ? ScalarFunction() : python_law(function, "coordinate '" + name + "'");
            return model.add_coordinate_law(body, coordinate, k.make(law_values(k.info(), values), f));
          },
          py::arg("body"), py::arg("coordinate"), py::arg("kind"), py::arg("values"), py::arg("function"),
          "Adds a law of `kind` on a joint coordinate (-1: the joint's only one); returns its index among the\n"
          "coordinate's laws.")
      .def(
          "_element_law",
          [](const Model& model, int k) {
            if (k < 0 || k >= static_cast<int>(model.force_elements().size()))
              bad("element", "a force element of this model", std::to_string(k));
            const ElementLaw& law = *model.force_elements()[k].law;
            return py::make_tuple(law.info().kind, law.values(), law.drawn_as());
          },
          py::arg("element"), "(kind, the constants' values, how it is drawn) of force element k's law.")
      .def_static(
          "_law_kinds",
          [] {
            py::list kinds;
            kinds.append(law_kind(SpringDamping::description(), false));
            for (const ElementLawKind& k : element_law_kinds()) kinds.append(law_kind(k.info(), true));
            for (const CoordinateLawKind& k : coordinate_law_kinds()) kinds.append(law_kind(k.info(), true));
            for (const ContactLawKind& k : contact_law_kinds()) kinds.append(law_kind(k.info(), true));
            return kinds;
          },
          "Every kind of law, each a dict: kind, acts_on ('element', 'coordinate' or 'contact'), doc, constants (name, unit,\n"
          "rotation_unit, default, lower, positive, doc, parameter, linear, upper), profile, profile_name, profile_units, function,\n"
          "addable (False: every coordinate's own spring-damping law).")
      .def_static(
          "_check_law",
          [](const std::string& kind, const py::dict& values, ProfilePtr profile) {
            std::shared_ptr<const Law> law;
            for (const ElementLawKind& k : element_law_kinds())
              if (kind == k.info().kind) law = k.make(law_values(k.info(), values), std::move(profile), {});
            for (const ContactLawKind& k : contact_law_kinds())
              if (kind == k.info().kind) law = k.make(law_values(k.info(), values));
            if (!law) {
              const CoordinateLawKind& k = coordinate_kind(kind);
              law = k.make(law_values(k.info(), values), {});
            }
            law->validate();
            return law->values();
          },
          py::arg("kind"), py::arg("values"), py::arg("profile"),
          "The constants' values of a law of `kind` (defaults for those not given), each converted and judged\n"
          "against its bounds (ValueError naming the first out of them).")
      .def(
          "_add_flow",
          [](Model& model, ProfilePtr length, int first, int elements) {
            Flow flow;
            flow.length = std::move(length);
            flow.first = first;
            flow.elements = elements;
            model.add_flow(std::move(flow));
          },
          py::arg("length"), py::arg("first"), py::arg("elements"))
      .def("_body_index", &Model::body_index, py::arg("name"))
      .def(
          "_body_name",
          [](const Model& model, int index) {
            if (index < 0 || index >= static_cast<int>(model.bodies().size())) bad("index", "a body index", std::to_string(index));
            return model.bodies()[index].name;
          },
          py::arg("index"))
      .def_property_readonly("id", &Model::id, "Unique id of this model, carried by its Body and Point handles.")
      .def("_adopt_id", &Model::adopt_id, py::arg("id"), "Takes the id of the model this one copies (unpickling).")
      .def("_coordinate_index", &Model::coordinate_index, py::arg("body"), py::arg("coordinate"))
      .def_property("gravity", &Model::gravity, &Model::set_gravity, "Gravitational acceleration (m/s^2), global.")
      .def_property_readonly("nbodies", [](const Model& model) { return model.bodies().size(); })
      .def_property_readonly("_nelements", [](const Model& model) { return model.force_elements().size(); })
      .def_property_readonly("_nloads", [](const Model& model) { return model.loads().size(); })
      .def_property_readonly("_nloops", [](const Model& model) { return model.loops().size(); })
      .def_property_readonly("_nflows", [](const Model& model) { return model.flows().size(); })
      .def_property_readonly("body_names", [](const Model& model) {
        std::vector<std::string> names;
        for (const auto& b : model.bodies()) names.push_back(b.name);
        return names;
      });
}

}  // namespace rigidfem::bindings

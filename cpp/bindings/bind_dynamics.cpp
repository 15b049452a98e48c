// System, Data and the named stages of the equations of motion: each binding calls one C++ function.
#include <algorithm>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "rigidfem/constraints.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/kinematics.hpp"
#include "rigidfem/outputs.hpp"
#include "rigidfem/parameters.hpp"

namespace rigidfem::bindings {

namespace {

using RefV = Eigen::Ref<const VecX>;

// One field of every free coordinate, in q order.
VecX free_coordinate_values(const System& s, double SpringDamping::*field) {
  VecX v(s.nq);
  for (int k = 0; k < s.nq; ++k) v(k) = s.coords[s.free_coords[k]].spring.*field;
  return v;
}

// The workspace of a call from Python: each thread keeps one Data per System for its four most
// recently called systems, so calls allocate nothing (a fresh Data costs as much as the dynamics
// from ~800 elements on). A call re-entered from a Python callback (a force law calling the
// system) gets a fresh Data while the outer call holds the kept one.
//
// It also answers Ctrl-C: while it lives, the long loops of the core (interruption_point) look at
// Python's signals (the calls hold the GIL) and stop with the KeyboardInterrupt.
class Workspace {
 public:
  explicit Workspace(const System& s) : interrupt_([] {
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }) {
    std::vector<Entry>& cache = entries();
    const std::weak_ptr<const System> me = s.weak_from_this();
    const auto same = [&me](const Entry& e) { return !e.system.owner_before(me) && !me.owner_before(e.system); };
    auto it = std::find_if(cache.begin(), cache.end(), same);
    if (it != cache.end() && it->busy) {
      fresh_ = std::make_unique<Data>(s);
      data_ = fresh_.get();
      return;
    }
    if (it == cache.end()) {
      cache.erase(std::remove_if(cache.begin(), cache.end(), [](const Entry& e) { return e.system.expired(); }),
                  cache.end());
      if (cache.size() >= 4) cache.pop_back();
      cache.insert(cache.begin(), Entry{me, std::make_unique<Data>(s), false});
      it = cache.begin();
    } else {
      std::rotate(cache.begin(), it, it + 1);  // most recent first
      it = cache.begin();
    }
    it->busy = true;
    data_ = it->data.get();
    data_->load_factor = 1.0;
    data_->loop_rank = -1;  // a call decides the loops' rank itself (a step's stages keep their projection's)
  }
  ~Workspace() {
    if (fresh_) return;
    for (Entry& e : entries())
      if (e.data.get() == data_) e.busy = false;
  }
  Workspace(const Workspace&) = delete;
  Workspace& operator=(const Workspace&) = delete;
  Data& operator*() { return *data_; }

 private:
  struct Entry {
    std::weak_ptr<const System> system;
    std::unique_ptr<Data> data;
    bool busy;
  };
  static std::vector<Entry>& entries() {
    thread_local std::vector<Entry> cache;
    return cache;
  }
  rigidfem::InterruptScope interrupt_;
  Data* data_ = nullptr;
  std::unique_ptr<Data> fresh_;
};

// Whether every number of a result is finite.
bool all_finite(double x) { return std::isfinite(x); }
template <class D>
bool all_finite(const Eigen::DenseBase<D>& m) { return m.allFinite(); }
template <class A, class B>
bool all_finite(const std::pair<A, B>& p) { return all_finite(p.first) && all_finite(p.second); }

// The result of a call whose inputs were finite: NaN or inf in it can only come from overflowing the range of
// doubles, a SimulationError naming the call, its time and the largest inputs.
template <class R, class... V>
R finite(R result, const char* call, double t, const V&... inputs) {
  if (all_finite(result)) return result;
  std::string sizes;
  ((sizes += (sizes.empty() ? "largest |" : ", largest |") + std::string(V::name) + "| = " + num(inputs.largest(), 3)),
   ...);
  throw SimulationError(t, std::string(call) + "() overflowed: finite inputs (" + sizes +
                               ") gave NaN or inf, beyond the range of doubles");
}

// The system and the workspace of a stage: ValueError naming the argument for another type.
const System& system_of(const py::handle& x) {
  if (!py::isinstance<System>(x)) bad("system", "a System from Model.compile()", arg_repr(x));
  return x.cast<const System&>();
}

Data& data_of(const py::handle& x) {
  if (!py::isinstance<Data>(x)) bad("data", "a workspace from system.make_data()", arg_repr(x));
  return x.cast<Data&>();
}

}  // namespace

void bind_dynamics(py::module_& m) {
  m.def(
      "_least_norm_symmetric", [](const MatX& A, const VecX& b, int rank) {
        if (A.rows() != A.cols() || b.size() != A.rows())
          throw std::invalid_argument("A, b: expected a square (n, n) array A and b of n numbers");
        return least_norm_symmetric(A, b, rank);
      },
      py::arg("A"),
      py::arg("b"),
      py::arg("rank") = -1,
      "x = A⁺ b for a symmetric positive semi-definite A (the loops' G M⁻¹ Gᵀ): its eigenvalues below 1e-10 of the "
      "largest count as zero; with rank >= 0, at most rank directions where the rest are small (constraints.hpp).");
  // Data is registered first, so that the signatures of System's methods name it (the stub's types).
  py::class_<Data> data(m, "Data",
      "Workspace of the algorithms; after each stage it holds that stage's results.\n"
      "\n"
      "Examples\n"
      "--------\n"
      ">>> import rigidfem as rf\n"
      ">>> model, h = rf.samples.pendulum()\n"
      ">>> system = model.compile()\n"
      ">>> data = system.make_data()\n"
      ">>> rf.stages.set_state(system, data, 0.0, [0.5], [0.0])\n"
      ">>> rf.stages.kinematics(system, data)\n"
      ">>> len(data.T), data.qa\n"
      "(1, array([0.5]))");
  py::class_<System, std::shared_ptr<System>>(m, "_System")
      // The System is immutable: only const methods are bound.
      .def(py::init([](const Model& model, const std::string& algorithm) {
             if (algorithm != "recursive" && algorithm != "lagrange")
               throw std::invalid_argument("algorithm: expected 'recursive' or 'lagrange', got '" + algorithm + "'");
             const Algorithm a = algorithm == "recursive" ? Algorithm::Recursive : Algorithm::Lagrange;
             return std::const_pointer_cast<System>(model.compile(a));
           }),
           py::arg("model"), py::arg("algorithm"))
      .def(py::init([](const System& base,
                       const std::vector<std::tuple<int, int, int, std::string, double>>& coordinates,
                       const std::vector<std::pair<int, Mat4>>& bodies,
                       const std::vector<std::tuple<int, std::string, double>>& elements,
                       const std::vector<std::tuple<int, Vec3, Vec3>>& loads,
                       const std::vector<std::tuple<std::string, int, int, ProfilePtr>>& profiles,
                       const std::vector<std::tuple<int, std::string, double>>& contacts) {
             // a copy of `base` with new constants and profiles (parameters.hpp): what named parameters set
             ConstantChanges c;
             for (const auto& [what, body, index, profile] : profiles) c.profiles.push_back({what, body, index, profile});
             for (const auto& [body, slot, law, name, value] : coordinates)
               c.coordinates.push_back({body, slot, law, name, value});
             for (const auto& [body, H] : bodies) c.bodies.push_back({body, H});
             for (const auto& [element, name, value] : elements) c.elements.push_back({element, name, value});
             for (const auto& [load, F, tau] : loads) c.loads.push_back({load, F, tau});
             for (const auto& [contact, name, value] : contacts) c.contacts.push_back({contact, name, value});
             return with_constants(base, c);
           }),
           py::arg("base"), py::arg("coordinates"), py::arg("bodies"), py::arg("elements"), py::arg("loads"),
           py::arg("profiles"), py::arg("contacts"))
      .def_property_readonly(
          "algorithm", [](const System& s) { return s.algorithm == Algorithm::Recursive ? "recursive" : "lagrange"; },
          "'recursive' (O(n): RNEA, CRBA, ABA) or 'lagrange' (the book's formulation; always for linear joints).")
      .def_readonly("nq", &System::nq, "Number of free joint coordinates (the unknowns).")
      .def_readonly("np", &System::np, "Number of prescribed (driven) coordinates.")
      .def_readonly("nc", &System::nc, "Number of all joint coordinates, nq + np.")
      .def_readonly("nbodies", &System::nbodies)
      .def_readonly("nz", &System::nz, "Number of Maxwell arms: internal variables s (their forces, N or N·m).")
      .def_property_readonly(
          "arms",
          [](const System& s) {
            RowMatX table(s.nz, 3);
            for (int j = 0; j < s.nz; ++j) table.row(j) << s.arms[j].q, s.arms[j].stiffness, s.arms[j].tau;
            return table;
          },
          "The Maxwell arms (nz, 3): free coordinate index, stiffness k (N/m or N·m/rad), relaxation time tau (s).")
      .def_readonly("body_names", &System::body_names)
      .def_readonly("parent", &System::parent, "Parent index of every body (-1: ground), parent[p] < p.")
      .def_readonly("gravity", &System::gravity, "Gravitational acceleration (m/s^2), global.")
      .def_property_readonly("coordinate_names", &System::coordinate_names,
                             "Names 'body.axis' of the free coordinates, in the order of q.")
      .def_property_readonly("prescribed_names", &System::prescribed_names,
                             "Names of the prescribed coordinates, in the order of driving_forces().")
      .def_property_readonly(
          "stiffness", [](const System& s) { return free_coordinate_values(s, &SpringDamping::stiffness); },
          "Spring stiffness c_i of each free coordinate (nq,), N/m or N m/rad.")
      .def_property_readonly(
          "damping", [](const System& s) { return free_coordinate_values(s, &SpringDamping::damping); },
          "Damping coefficient b_i of each free coordinate (nq,), N s/m or N m s/rad.")
      .def_property_readonly(
          "rest", [](const System& s) { return free_coordinate_values(s, &SpringDamping::rest); },
          "Spring rest value q_i^0 of each free coordinate (nq,), m or rad.")
      .def_readonly("masses", &System::mass, "Mass of every body (nbodies), kg.")
      .def_readonly("centres_of_mass", &System::com, "Centre of mass of every body in its own frame (m).")
      .def_readonly("inertias", &System::inertia,
                    "Inertia tensor (3, 3) of every body about its centre of mass, body axes (kg m^2).")
      .def_property_readonly("pseudo_inertias", [](const System& s) { return s.H; },
                             "Pseudo-inertia H_p = int r r^T dm (4, 4) of every body, body frame (kg, kg m, kg m^2).")
      .def_property_readonly("placements", [](const System& s) { return s.B; },
                             "Constant joint placements B_p (4, 4) in the parent frame.")
      .def_readonly("nl", &System::nl, "Number of constraint equations of the loop closures (multipliers).")
      .def_property_readonly(
          "loop_names",
          [](const System& s) {
            std::vector<std::string> names;
            for (const Loop& L : s.loops) names.push_back(L.name);
            return names;
          },
          "Names of the loop closures, in the order of loop_reactions().")
      .def_property_readonly(
          "loop_kinds",
          [](const System& s) {
            std::vector<std::string> kinds;
            for (const Loop& L : s.loops) kinds.push_back(loop_kind_name(L.kind));
            return kinds;
          },
          "Kind of every loop closure ('revolute', ..., 'distance').")
      .def(
          "loop_constraints",
          [](const System& s, Time t, Coordinates q, Rates qd) {
            Workspace d(s);
            loop_equations(s, *d, t, q, qd);
            return py::make_tuple(VecX((*d).g), VecX((*d).gd), free_jacobian(s, *d));
          },
          py::arg("t"), py::arg("q"), py::arg("qd"),
          "(g, gd, G): the loop closures' constraint equations g(q, t) (nl,) (m, or the cosine for direction\n"
          "rows), their rates gd = G qd + dg/dt (nl,) and the Jacobian G = dg/dq (nl, nq).\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.four_bar()\n"
          ">>> system = model.compile()\n"
          ">>> q, qd = system.assemble([0.4, -1.9, 4.6])\n"
          ">>> g, gd, G = system.loop_constraints(0.0, q, qd)\n"
          ">>> bool(abs(g).max() < 1e-10), G.shape\n"
          "(True, (5, 3))")
      .def(
          "loop_multipliers",
          [](const System& s, Time t, Coordinates q, Rates qd) {
            Workspace d(s);
            rigidfem::forward_dynamics(s, *d, t, q, qd);
            return finite(VecX((*d).lambda), "loop_multipliers", t, q, qd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"),
          "Multipliers lambda (nl,) of M qdd = f + G^T lambda at the forward-dynamics accelerations.\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.four_bar()\n"
          ">>> system = model.compile()\n"
          ">>> q, qd = system.assemble([0.4, -1.9, 4.6])\n"
          ">>> system.loop_multipliers(0.0, q, qd).shape, system.nl\n"
          "((5,), 5)")
      .def(
          "loop_reactions",
          [](const System& s, Time t, Coordinates q, Rates qd) {
            Workspace d(s);
            rigidfem::forward_dynamics(s, *d, t, q, qd);
            return finite(rigidfem::loop_reactions(s, *d, (*d).lambda), "loop_reactions", t, q, qd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"),
          "Reaction of every loop closure on its body b (nloops, 6): force (N) and torque (N m, about frame B's\n"
          "origin) in frame A's axes; for a distance loop (an actuator) the force along the line in column 0,\n"
          "positive pushing b away from a.\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.four_bar()\n"
          ">>> system = model.compile()\n"
          ">>> q, qd = system.assemble([0.4, -1.9, 4.6])\n"
          ">>> system.loop_names, system.loop_reactions(0.0, q, qd).shape\n"
          "(['C'], (1, 6))")
      .def_property_readonly(
          "element_names",
          [](const System& s) {
            std::vector<std::string> names;
            for (const ForceElement& E : s.elements) names.push_back(E.name);
            return names;
          },
          "Names of the force elements (spring-dampers, cylinders, ropes), in the order of element_states().")
      .def_property_readonly(
          "_segments",
          [](const System& s) {
            // what the viewer draws between two points: each force element as its law says, each loop (an actuator
            // as one, the others as a joint between their frames' origins)
            py::list out;
            for (const ForceElement& E : s.elements)
              out.append(py::make_tuple(E.law->drawn_as(), E.body_a, E.point_a, E.body_b, E.point_b));
            for (const Loop& L : s.loops)
              out.append(py::make_tuple(L.actuator ? "actuator" : "loop", L.body_a,
                                        Vec3(L.frame_a.topRightCorner<3, 1>()), L.body_b,
                                        Vec3(L.frame_b.topRightCorner<3, 1>())));
            return out;
          },
          "(how it is drawn, body a, point on a (m), body b, point on b) of every force element and loop.")
      .def_property_readonly(
          "_shapes",
          [](const System& s) {
            // what the viewer draws of each shape, in its body's frame
            py::list out;
            for (const Shape& shape : s.shapes)
              out.append(py::make_tuple(shape_kind_name(shape.kind), shape.body, shape.a, shape.b, shape.n, shape.h,
                                        shape.R, shape.radius));
            return out;
          },
          "(kind, body, a, b, normal, half_extents, rotation, radius) of every shape (contact.hpp).")
      .def_property_readonly(
          "contact_names",
          [](const System& s) {
            std::vector<std::string> names;
            for (const Contact& C : s.contacts) names.push_back(C.name);
            return names;
          },
          "Names of the contacts (Model.add_contact).")
      .def(
          "contact_states",
          [](const System& s, Time t, Coordinates q, Rates qd) {
            Workspace d(s);
            set_state(s, *d, t, q, qd);
            kinematics(s, *d);
            py::list out;
            for_each_contact_force(s, *d, false, [&](const ContactForce& c) {
              out.append(py::dict(py::arg("contact") = s.contacts[c.contact].name, py::arg("a") = c.body_a,
                                  py::arg("b") = c.body_b, py::arg("point") = c.x, py::arg("normal") = c.n,
                                  py::arg("gap") = c.gap, py::arg("gap_rate") = c.gap_rate,
                                  py::arg("normal_force") = c.Fn, py::arg("force") = c.f, py::arg("slip") = c.vt));
            });
            return out;
          },
          py::arg("t"), py::arg("q"), py::arg("qd"),
          "Every overlap of two shapes of a contact at (t, q, qd), each a dict: contact (its name), a and b (the\n"
          "bodies' indices, -1 the ground), point (the contact point, m), normal (from a to b), gap (m, < 0: the\n"
          "penetration), gap_rate (m/s), normal_force (N), force (on b, N; -force on a), slip (m/s).\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model = rf.Model()\n"
          ">>> ball = model.add_body(\"ball\", model.ground, rf.Joint.prismatic(\"z\"), mass=0.1,\n"
          "...                       inertia=(1e-5,) * 3)\n"
          ">>> b = model.add_shape(\"sphere\", ball, rf.shapes.Sphere(0.05))\n"
          ">>> floor = model.add_shape(\"floor\", model.ground, rf.shapes.HalfSpace())\n"
          ">>> _ = model.add_contact(\"hit\", b, floor, rf.laws.Contact(stiffness=1e5, restitution=0.8))\n"
          ">>> system = model.compile()\n"
          ">>> system.contact_states(0.0, [0.1], [0.0])\n"
          "[]\n"
          ">>> (c,) = system.contact_states(0.0, [0.04], [0.0])\n"
          ">>> c[\"contact\"], round(c[\"gap\"], 4), round(c[\"normal_force\"], 1)\n"
          "('hit', -0.01, 100.0)")
      .def(
          "element_states",
          [](const System& s, Time t, Coordinates q, Rates qd) {
            Workspace d(s);
            return finite(rigidfem::element_states(s, *d, t, q, qd), "element_states", t, q, qd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"),
          "Length l (m), rate dl/dt (m/s) and axial force F (N, positive pushing the two points apart) of every\n"
          "force element (nelements, 3).\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model = rf.Model(gravity=None)\n"
          ">>> block = model.add_body(\"block\", model.ground, rf.Joint.prismatic(\"x\"), mass=2.0,\n"
          "...                        inertia=(1e-3,) * 3)\n"
          ">>> _ = model.add_spring_damper(\"s\", model.ground, block, stiffness=50.0, length=0.0, damping=1.0)\n"
          ">>> system = model.compile()\n"
          ">>> system.element_names\n"
          "['s']\n"
          ">>> system.element_states(0.0, [0.1], [0.0]).round(4)\n"
          "array([[ 0.1,  0. , -5. ]])")

      .def(
          "_assemble",
          [](const System& s, Time t, Coordinates q, Rates qd, double tol, int max_iterations) {
            Workspace d(s);
            VecX x = q.vector(), xd = qd.vector();
            project_onto_loops(s, *d, t, x, xd, tol, max_iterations);
            return py::make_tuple(x, xd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("tol"), py::arg("max_iterations"))
      .def(
          "_assemble_and_accelerate",
          [](const System& s, Time t, Coordinates q, Rates qd, double tol, int max_iterations,
             std::optional<std::pair<Coordinates, Rates>> stage) {
            Workspace d(s);
            VecX x = q.vector(), xd = qd.vector();
            const VecX xdd = project_and_forward_dynamics(s, *d, t, x, xd, tol, max_iterations);
            if (!stage) return py::tuple(py::make_tuple(x, xd, xdd));
            const VecX sdd = rigidfem::forward_dynamics(s, *d, t, stage->first.vector(), stage->second.vector());
            return py::tuple(py::make_tuple(x, xd, xdd, sdd));
          },
          py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("tol"), py::arg("max_iterations"),
          py::arg("stage") = py::none(),
          "(q, q̇, q̈): _assemble, then the forward dynamics at the state it reached, on the projection's own "
          "factorisation (what the integrators do after each step on loops); with stage = (q_s, q̇_s), also q̈ "
          "there with the same workspace, as a step's stages evaluate it (the rank kept on the loops).")
      .def(
          "forward_dynamics", [](const System& s, Time t, Coordinates q, Rates qd) {
            Workspace d(s);
            return finite(VecX(rigidfem::forward_dynamics(s, *d, t, q, qd)), "forward_dynamics", t, q, qd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"),
          "Accelerations qdd (nq,) solving A(q) qdd = f(q, qd, t); t in s, q in m/rad, qd in m/s, rad/s.\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> system.forward_dynamics(0.0, [0.5], [0.0]).round(4)\n"
          "array([-7.0547])")
      .def(
          "mass_matrix", [](const System& s, Time t, Coordinates q) {
            Workspace d(s);
            return finite(rigidfem::mass_matrix(s, *d, t, q), "mass_matrix", t, q);
          },
          py::arg("t"), py::arg("q"),
          "Mass matrix A(q) (nq, nq), a_ij = sum_p tr(T_p,i H_p T_p,j^T).\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> system.mass_matrix(0.0, [0.0]).round(4)\n"
          "array([[0.3333]])")
      .def(
          "generalized_forces",
          [](const System& s, Time t, Coordinates q, Rates qd, LoadFactor load_factor) {
            Workspace d(s);
            return finite(rigidfem::generalized_forces(s, *d, t, q, qd, load_factor), "generalized_forces", t, q, qd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("load_factor") = 1.0,
          "Right-hand side f (nq,) of A qdd = f: loads, gravity, springs, dampers minus velocity terms (N, N m).\n"
          "load_factor scales gravity, loads and applied generalised forces.\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> system.generalized_forces(0.0, [0.5], [0.0]).round(4)\n"
          "array([-2.3516])")
      .def(
          "static_forces",
          [](const System& s, Time t, Coordinates q, LoadFactor load_factor) {
            Workspace d(s);
            return finite(rigidfem::static_forces(s, *d, t, q, load_factor), "static_forces", t, q);
          },
          py::arg("t"), py::arg("q"), py::arg("load_factor") = 1.0,
          "Static residual f(q) (nq,): generalised forces at rest, prescribed coordinates held at their values at t.\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> system.static_forces(0.0, [0.5]).round(4)\n"
          "array([-2.3516])")
      .def(
          "force_jacobians",
          [](const System& s, Time t, Coordinates q, Rates qd, LoadFactor load_factor, StaticFlag static_drives) {
            if (static_drives) check_vector(qd, s.nq, "qd", "nq");  // unread then, but judged all the same
            Workspace d(s);
            return finite(rigidfem::force_jacobians(s, *d, t, q, qd, load_factor, static_drives), "force_jacobians", t, q, qd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("load_factor") = 1.0, py::arg("static") = false,
          "(df/dq, df/dqd), each (nq, nq): analytic for recursive systems, central differences for\n"
          "algorithm='lagrange'. -df/dq is the tangent stiffness K,\n"
          "-df/dqd the damping and gyroscopic matrix C. static=True holds the prescribed coordinates at t.\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> dfdq, dfdqd = system.force_jacobians(0.0, [0.0], [0.0])\n"
          ">>> dfdq.round(4), dfdqd.round(4) + 0.0\n"
          "(array([[-4.905]]), array([[0.]]))")
      .def(
          "driving_forces", [](const System& s, Time t, Coordinates q, Rates qd) {
            Workspace d(s);
            return finite(rigidfem::driving_forces(s, *d, t, q, qd), "driving_forces", t, q, qd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"),
          "Forces/torques (np,) the drives exert on the prescribed coordinates (N or N m).\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model = rf.Model()\n"
          ">>> arm = model.add_body(\"arm\", model.ground, rf.Joint.revolute(\"y\"), mass=1.0,\n"
          "...                      inertia=(0.1, 0.1, 0.1), com=(0.5, 0.0, 0.0))\n"
          ">>> _ = model.prescribe(arm, rf.motion.ramp(1.0, 0.0, 1.0))\n"
          ">>> system = model.compile()\n"
          ">>> system.prescribed_names\n"
          "['arm.ry']\n"
          ">>> system.driving_forces(0.0, [], []).round(4)\n"
          "array([-4.905])")
      .def(
          "rhs", [](const System& s, Time t, States y) {
            Workspace d(s);
            return finite(rigidfem::rhs(s, *d, t, y), "rhs", t, y);
          },
          py::arg("t"), py::arg("y"), "dy/dt = [qd, qdd] for y = [q, qd] (2 nq,): the signature of scipy's solve_ivp.\n"
          "With loop closures qdd holds them at the acceleration level only: g(q) = 0 drifts under solve_ivp\n"
          "(rigidfem.simulate's methods project onto the loops).\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> system.rhs(0.0, [0.5, 1.0]).round(4)\n"
          "array([ 1.    , -7.0547])")
      .def(
          "jacobian", [](const System& s, Time t, States y) {
            Workspace d(s);
            return finite(rhs_jacobian(s, *d, t, y), "jacobian", t, y);
          },
          py::arg("t"), py::arg("y"), "d(rhs)/dy (2 nq, 2 nq) for solve_ivp(jac=...): analytic for recursive systems (see\n"
          "acceleration_derivatives), central differences for algorithm='lagrange'.\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> system.jacobian(0.0, [0.0, 0.0]).round(4) + 0.0\n"
          "array([[  0.   ,   1.   ],\n"
          "       [-14.715,   0.   ]])")
      .def(
          "inverse_dynamics",
          [](const System& s, Time t, Coordinates q, Rates qd, Accelerations qdd) {
            Workspace d(s);
            return finite(rigidfem::inverse_dynamics(s, *d, t, q, qd, qdd), "inverse_dynamics", t, q, qd, qdd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("qdd"),
          "r = A(q) qdd - f(q, qd, t) (nq,): the generalised forces (N or N m) the free coordinates\n"
          "need besides the loads, springs and dampers to move with qdd (the residual of the\n"
          "equations of motion; zero at the forward-dynamics accelerations).\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> qdd = system.forward_dynamics(0.0, [0.5], [0.0])\n"
          ">>> bool(abs(system.inverse_dynamics(0.0, [0.5], [0.0], qdd)).max() < 1e-12)\n"
          "True")
      .def(
          "inverse_dynamics_derivatives",
          [](const System& s, Time t, Coordinates q, Rates qd, Accelerations qdd) {
            Workspace d(s);
            return finite(rigidfem::inverse_dynamics_derivatives(s, *d, t, q, qd, qdd), "inverse_dynamics_derivatives", t, q, qd, qdd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("qdd"),
          "(dr/dq, dr/dqd), each (nq, nq), of r = A qdd - f: analytic through the RNEA for recursive\n"
          "systems (O(n) per column), central differences for algorithm='lagrange'.\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> drdq, drdqd = system.inverse_dynamics_derivatives(0.0, [0.0], [0.0], [0.0])\n"
          ">>> drdq.round(4), drdqd.round(4) + 0.0\n"
          "(array([[4.905]]), array([[0.]]))")
      .def(
          "_inverse_dynamics_direction",
          [](const System& s, Time t, Coordinates q, Rates qd, Accelerations qdd, const VecX& dq, const VecX& dqd,
             const VecX& dqdd) {
            check_vector(dq, s.nq, "dq", "nq"), check_vector(dqd, s.nq, "dqd", "nq"), check_vector(dqdd, s.nq, "dqdd", "nq");
            Workspace d(s);
            return rigidfem::inverse_dynamics_direction(s, *d, t, q, qd, qdd, dq, dqd, dqdd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("dq"), py::arg("dqd"), py::arg("dqdd"),
          "(dr/dq) dq + (dr/dqd) dqd + A dqdd (nq): the RNEA's forward-mode derivative along one direction (recursive:\n"
          "exact, O(n)), central differences (lagrange).")
      .def(
          "_inverse_dynamics_vjp",
          [](const System& s, Time t, Coordinates q, Rates qd, Accelerations qdd, const VecX& mu) {
            check_vector(mu, s.nq, "mu", "nq");
            Workspace d(s);
            const ResidualVjp r = rigidfem::inverse_dynamics_vjp(s, *d, t, q, qd, qdd, mu);
            return py::make_tuple(r.q, r.qd, r.qdd, r.pq, r.pqd, r.pqdd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("mu"),
          "((dr/dq)^T mu, (dr/dqd)^T mu, A mu), each (nq), and d(mu^T r)/d of the prescribed coordinates' q, qd,\n"
          "qdd, each (np): the RNEA's reverse mode (recursive systems), O(n).")
      .def(
          "acceleration_derivatives",
          [](const System& s, Time t, Coordinates q, Rates qd) {
            Workspace d(s);
            return finite(rigidfem::acceleration_derivatives(s, *d, t, q, qd), "acceleration_derivatives", t, q, qd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"),
          "(dqdd/dq, dqdd/dqd), each (nq, nq): -A^-1 (dr/dq, dr/dqd) at the forward-dynamics qdd; with loop\n"
          "closures, of the constrained qdd (multipliers and constraint Jacobian varying too), by central differences.\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> dq, dqd = system.acceleration_derivatives(0.0, [0.0], [0.0])\n"
          ">>> dq.round(4), dqd.round(4) + 0.0\n"
          "(array([[-14.715]]), array([[0.]]))")
      .def(
          "transform", [](const System& s, BodyArgument body, Time t, Coordinates q) {
            Workspace d(s);
            return finite(body_pose(s, *d, body, t, q), "transform", t, q);
          },
          py::arg("body"), py::arg("t"), py::arg("q"), "Pose T_p (4, 4) of a body (by index) in the global frame.")
      .def(
          "_position", [](const System& s, PointArgument p, Time t, Coordinates q) {
            Workspace d(s);
            return finite(point_position(s, *d, p, t, q), "position", t, q);
          },
          py::arg("point"), py::arg("t"), py::arg("q"))
      .def(
          "_positions",
          [](const System& s, PointsArgument points, Time t, Coordinates q) {
            Workspace d(s);
            return finite(point_positions(s, *d, points, t, q), "positions", t, q);
          },
          py::arg("points"), py::arg("t"), py::arg("q"))
      .def(
          "_velocity", [](const System& s, PointArgument p, Time t, Coordinates q, Rates qd) {
            Workspace d(s);
            return finite(point_velocity(s, *d, p, t, q, qd), "velocity", t, q, qd);
          },
          py::arg("point"), py::arg("t"), py::arg("q"), py::arg("qd"))
      .def(
          "kinetic_energy", [](const System& s, Time t, Coordinates q, Rates qd) {
            Workspace d(s);
            return finite(energies(s, *d, t, q, qd).kinetic, "kinetic_energy", t, q, qd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"),
          "Kinetic energy 1/2 sum tr(dT H dT^T) (J).\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> round(system.kinetic_energy(0.0, [0.0], [2.0]), 4)\n"
          "0.6667")
      .def(
          "gravity_energy", [](const System& s, Time t, Coordinates q) {
            Workspace d(s);
            return finite(energies(s, *d, t, q, VecX::Zero(s.nq)).gravity, "gravity_energy", t, q);
          },
          py::arg("t"), py::arg("q"),
          "Potential energy of gravity -sum m g^T r_C (J).\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> round(system.gravity_energy(0.0, [0.0]), 4)\n"
          "-4.905")
      .def(
          "elastic_energy", [](const System& s, Time t, Coordinates q) {
            Workspace d(s);
            return finite(energies(s, *d, t, q, VecX::Zero(s.nq)).elastic, "elastic_energy", t, q);
          },
          py::arg("t"), py::arg("q"), "Energy of the joint springs 1/2 sum c (q - q_rest)^2 and of the force elements' springs\n"
          "1/2 sum k (l - l0)^2 (J).\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model = rf.Model(gravity=None)\n"
          ">>> block = model.add_body(\"block\", model.ground, rf.Joint.prismatic(\"x\"), mass=2.0,\n"
          "...                        inertia=(1e-3,) * 3)\n"
          ">>> _ = model.add_spring_damper(\"s\", model.ground, block, stiffness=50.0, length=0.0, damping=1.0)\n"
          ">>> system = model.compile()\n"
          ">>> round(system.elastic_energy(0.0, [0.1]), 4)\n"
          "0.25")
      .def(
          "potential_energy", [](const System& s, Time t, Coordinates q) {
            Workspace d(s);
            return finite(energies(s, *d, t, q, VecX::Zero(s.nq)).potential(), "potential_energy", t, q);
          },
          py::arg("t"), py::arg("q"),
          "Gravity plus elastic energy (J).\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> round(system.potential_energy(0.0, [0.0]), 4)\n"
          "-4.905")
      .def(
          "dissipated_power", [](const System& s, Time t, Coordinates q, Rates qd) {
            Workspace d(s);
            return finite(energies(s, *d, t, q, qd).dissipated, "dissipated_power", t, q, qd);
          },
          py::arg("t"), py::arg("q"), py::arg("qd"), "Power dissipated by the joint dampers, sum b qd^2, and by the force elements' dampers,\n"
          "sum c (dl/dt)^2 (W).\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model = rf.Model(gravity=None)\n"
          ">>> block = model.add_body(\"block\", model.ground, rf.Joint.prismatic(\"x\"), mass=2.0,\n"
          "...                        inertia=(1e-3,) * 3)\n"
          ">>> _ = model.add_spring_damper(\"s\", model.ground, block, stiffness=50.0, length=0.0, damping=1.0)\n"
          ">>> system = model.compile()\n"
          ">>> round(system.dissipated_power(0.0, [0.1], [1.0]), 4)\n"
          "1.0")
      .def(
          "make_data", [](const System& s) { return std::make_unique<Data>(s); },
          "A fresh workspace for the stage functions (allocated in place: a Data is never copied or moved).\n"
          "\n"
          "Examples\n"
          "--------\n"
          ">>> import rigidfem as rf\n"
          ">>> model, h = rf.samples.pendulum()\n"
          ">>> system = model.compile()\n"
          ">>> data = system.make_data()\n"
          ">>> type(data).__name__\n"
          "'Data'");

  data.def_readonly("t", &Data::t)
      .def_readonly("qa", &Data::qa, "All coordinates (nc,), free and prescribed.")
      .def_readonly("qda", &Data::qda)
      .def_readonly("qdda", &Data::qdda)
      .def_readonly("T", &Data::T, "Global pose T_p (4, 4) of every body.")
      .def_readonly("Td", &Data::Td, "dT_p/dt.")
      .def_readonly("Tdd", &Data::Tdd, "d2T_p/dt2 (with the free accelerations zero unless driving_forces ran).")
      .def_readonly("U", &Data::U, "U (4, 4) of every coordinate use: dT_p/dq_i = U_i T_p for the bodies p below\n"
                                   "coordinate i (without linear-model couplings, use i is coordinate i).")
      .def_readonly("Hbar", &Data::Hbar, "Subtree sums of T_p H_p T_p^T.")
      .def_readonly("Wbar", &Data::Wbar, "Subtree sums of T_p H_p Tdd_p^T.")
      .def_readonly("Zbar", &Data::Zbar, "Subtree sums of the load moments.")
      .def_readonly("A", &Data::A, "Mass matrix (nq, nq).")
      .def_readonly("f", &Data::f, "Right-hand side (nq,).")
      .def_readonly("qdd", &Data::qdd, "Accelerations (nq,).")
      .def_readonly("tau", &Data::tau, "Driving forces (np,).");

  auto stages = m.def_submodule("stages", "The named stages of forward dynamics, each writing into a Data.");
  stages.def(
      "set_state",
      [](const py::object& s, const py::object& d, Time t, Coordinates q, Rates qd) {
        rigidfem::set_state(system_of(s), data_of(d), t, q, qd);
      },
      py::arg("system"), py::arg("data"), py::arg("t"), py::arg("q"), py::arg("qd"),
      "(t, q, qd) => data.qa, qda, qdda (drives evaluated).");
  stages.def(
      "kinematics", [](const py::object& s, const py::object& d) { rigidfem::kinematics(system_of(s), data_of(d)); },
      py::arg("system"), py::arg("data"), "(qa, qda, qdda) => data.T, Td, Tdd, U.");
  stages.def(
      "generalized_forces",
      [](const py::object& s, const py::object& d) {
        rigidfem::generalized_forces(system_of(s), data_of(d));
        return data_of(d).f;
      },
      py::arg("system"), py::arg("data"), "=> data.f (loads, velocity terms, springs, dampers); returns it.");
  stages.def(
      "mass_matrix",
      [](const py::object& s, const py::object& d) {
        rigidfem::mass_matrix(system_of(s), data_of(d));
        return data_of(d).A;
      },
      py::arg("system"), py::arg("data"), "=> data.A; returns it.");
  stages.def(
      "accelerations",
      [](const py::object& s, const py::object& d) {
        rigidfem::accelerations(system_of(s), data_of(d));
        return data_of(d).qdd;
      },
      py::arg("system"), py::arg("data"), "=> data.qdd solving A qdd = f; returns it.");
  stages.def(
      "driving_forces",
      [](const py::object& s, const py::object& d) {
        rigidfem::driving_forces(system_of(s), data_of(d));
        return data_of(d).tau;
      },
      py::arg("system"), py::arg("data"), "=> data.tau (needs accelerations); returns it.");
}

}  // namespace rigidfem::bindings

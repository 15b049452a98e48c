/// The mutable description of a multibody system (bodies, joints, springs, drives,
/// loads) and its compilation into an immutable System (see system.hpp).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "rigidfem/contact.hpp"
#include "rigidfem/coordinate_laws.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/flows.hpp"
#include "rigidfem/force_elements.hpp"
#include "rigidfem/joint_motion.hpp"
#include "rigidfem/loops.hpp"
#include "rigidfem/profiles.hpp"

namespace rigidfem {

class System;
enum class Algorithm;

/// A joint: the active elementary motions, in the book's order x, y, z, φ3, φ2, φ1,
/// with a linear spring (stiffness, rest value) and a viscous damper on each.
struct Joint {
  std::vector<Axis> axes;
  std::vector<double> stiffness;  ///< (ncoords) N/m or N·m/rad
  std::vector<double> rest;       ///< (ncoords) m or rad
  std::vector<double> damping;    ///< (ncoords) N·s/m or N·m·s/rad
  std::string kind;               ///< "revolute", "free", ... (for printing)
  /// Linear joint: T̃ = 1 + Σ_k G_k q_k, first order in its coordinates (G_k the
  /// elementary generators for its own coordinates). Used by the book's linear model.
  bool linear = false;
  /// A coordinate of an earlier body that also moves this (linear) joint, with its
  /// generator G in this joint's frame. In the linear model of a link, rfe i hangs on
  /// rfe 0 and moves with the coordinates of every sde up to i.
  struct Coupling {
    int body;
    int slot;
    Mat4 G;
  };
  std::vector<Coupling> coupled;

  /// Joint with the given axes (any order; stored in the book's order), no springs.
  static Joint make(const std::string& kind, std::vector<Axis> axes);
  int ncoords() const { return static_cast<int>(axes.size()); }
};

/// A handle to a body; index −1 is the ground. `model` is the id of the Model that made it
/// (0: unknown, e.g. a handle built by hand), so that a System can refuse another model's handles.
struct Body {
  int index = -1;
  std::string name = "ground";
  std::uint64_t model = 0;
};

/// A material point of a body, r in the body frame (m); `model` as in Body.
struct Point {
  int body = -1;
  Vec3 r = Vec3::Zero();
  std::uint64_t model = 0;
  Point() = default;
  Point(int b, const Vec3& r_, std::uint64_t model_ = 0) : body(b), r(r_), model(model_) {}
  Point(const Body& b) : body(b.index), r(Vec3::Zero()), model(b.model) {}  // NOLINT: implicit, the body's origin
};

/// Generalised force law Q(t, q, q̇) of one coordinate (the slow path through Python).
using ForceLaw = ScalarFunction;

/// A force law that returned no finite number. Called by a System method it is bad input (its
/// what() reads "force: expected ..., got ...", Python ValueError); inside a simulation the
/// integrator reports it as the SimulationError at its time and cause.
class ForceLawError : public SimulationError {
 public:
  ForceLawError(double t, const std::string& cause, std::string message)
      : SimulationError(t, cause), message_(std::move(message)) {}
  const char* what() const noexcept override { return message_.c_str(); }

 private:
  std::string message_;
};

/// A point force and/or torque on a body. Global components, or body components
/// when follower; optionally scaled in time by a profile's value.
struct Load {
  int body = -1;
  Vec3 point = Vec3::Zero();   ///< m, body frame
  Vec3 force = Vec3::Zero();   ///< N
  Vec3 torque = Vec3::Zero();  ///< N·m
  bool follower = false;
  ProfilePtr scale;  ///< null: constant
};

/// Per-body description as given by the user.
struct BodySpec {
  std::string name;
  int parent = -1;
  Mat4 placement = Mat4::Identity();  ///< T of the joint frame in the parent frame
  Joint joint;
  double mass = 0.0;
  Vec3 com = Vec3::Zero();
  Mat3 inertia = Mat3::Zero();  ///< about the centre of mass, body axes (kg·m²)
};

/// A Maxwell arm on a joint coordinate (the viscoelastic sde laws: Zener, Prony series): a spring
/// k in series with a dashpot k τ, in parallel with the coordinate's own spring and damper. Its
/// force s (N or N·m, > 0 resisting q − q⁰) is an internal variable of the state,
///   ṡ = k q̇ − s / τ,   Q = −s on the coordinate,
/// storing s² / (2k) and dissipating s² / (k τ).
struct MaxwellArm {
  double stiffness = 0.0;  ///< k, N/m or N·m/rad
  double tau = 0.0;        ///< τ, s: the arm's relaxation time
};

/// What the user says about one joint coordinate beyond its spring and damper.
struct CoordinateSpec {
  ProfilePtr drive;         ///< prescribed motion, or null
  double force = 0.0;       ///< constant applied generalised force (N or N·m)
  std::vector<std::shared_ptr<const CoordinateLaw>> laws;  ///< further laws (coordinate_laws.hpp), in order
  std::vector<MaxwellArm> arms;  ///< Maxwell arms (free coordinates only: compile checks)
};

/// Pseudo-inertia H = ∫ r rᵀ dm (4x4, body frame) of a body of mass m, centre of
/// mass c and inertia tensor I_C about c: H = [[½ tr(I_O) 1 − I_O, m c], [m cᵀ, m]]
/// with I_O = I_C + m(|c|² 1 − c cᵀ) the inertia about the body origin.
Mat4 pseudo_inertia(double mass, const Vec3& com, const Mat3& inertia);

class Model {
 public:
  explicit Model(const Vec3& gravity = Vec3(0.0, 0.0, -9.81));

  /// Adds a body on `parent` (−1: ground); returns its handle. Throws
  /// std::invalid_argument naming the argument for every bad value.
  Body add_body(const std::string& name, int parent, const Joint& joint, const Mat4& placement, double mass,
                const Vec3& com, const Mat3& inertia);
  /// Adds several bodies at once, in order (a parent may be an earlier body of the same batch):
  /// all are checked before any is added, so a bad one leaves the model unchanged. O(n).
  std::vector<Body> add_bodies(std::vector<BodySpec> bodies);
  /// Removes the bodies n, n + 1, ... (the last added) with their drives, forces and loads: undoes
  /// a builder that failed halfway (no remaining body refers to them: parents come first).
  void truncate(int n);
  /// Prescribes coordinate `coordinate` (−1: the joint's only one) of a body's joint, once.
  void prescribe(int body, int coordinate, ProfilePtr motion);
  /// Adds a constant generalised force, or a law Q(t, q, q̇) (a ForceFunction: at most one), on one joint coordinate.
  void add_generalized_force(int body, int coordinate, double value, ForceLaw law);
  /// Adds a law (coordinate_laws.hpp) on one joint coordinate (−1: the joint's only one), its constants checked;
  /// returns its index among that coordinate's laws.
  int add_coordinate_law(int body, int coordinate, std::shared_ptr<const CoordinateLaw> law);
  /// The laws of a body's joint coordinate (−1: the joint's only one), in order.
  const std::vector<std::shared_ptr<const CoordinateLaw>>& coordinate_laws(int body, int coordinate) const;
  /// Adds a Maxwell arm (stiffness k > 0, relaxation time τ > 0) on one joint coordinate.
  void add_maxwell_arm(int body, int coordinate, const MaxwellArm& arm);
  void add_load(const Load& load);
  /// Closes a loop (loops.hpp); returns its index. Checks the bodies, frames, length and name (non-empty, new
  /// among the loops').
  int add_loop(const Loop& loop);
  /// Makes the beam of rfes flow.first .. flow.first + flow.elements a link of varying free length
  /// L(t) (flows.hpp): checks the chain and the length, sets L₀ = L(0) and prescribes the first
  /// ("x") coordinate of every sde joint with its growth κ_k (L(t) − L₀).
  void add_flow(Flow flow);
  /// Adds a force element between two bodies (force_elements.hpp); returns its index. Checks the
  /// bodies, points, parameters and name (non-empty, new among the elements').
  int add_force_element(const ForceElement& element);
  /// Winds force element `element` (a law that winds: a rope) on coordinate `coordinate` (−1: the only one) of body
  /// `body`'s joint, a drum of radius `radius` (m; non-zero, negative to pay in as it turns forward) or a sheave's slip:
  /// its unstretched length gains r q, and the coordinate takes r P c (Winding: the capstan's μθ and v_ε).
  void wind(int element, int body, int coordinate, double radius, double capstan = 0.0, double smoothing = 0.0);
  /// Adds a shape fixed on a body (contact.hpp); returns its index. Checks the body, the geometry and the name.
  int add_shape(const Shape& shape);
  /// Adds a contact between two groups of shapes (contact.hpp); returns its index. Checks the shapes, their pairs
  /// (a box touches half-spaces only, two half-spaces never touch, at least one pair on two bodies), the law and
  /// the name.
  int add_contact(const Contact& contact);
  void set_gravity(const Vec3& g);

  const Vec3& gravity() const { return gravity_; }
  const std::vector<BodySpec>& bodies() const { return bodies_; }
  const std::vector<Loop>& loops() const { return loops_; }
  const std::vector<Flow>& flows() const { return flows_; }
  const std::vector<ForceElement>& force_elements() const { return elements_; }
  const std::vector<Shape>& shapes() const { return shapes_; }
  const std::vector<Contact>& contacts() const { return contacts_; }
  const std::vector<Load>& loads() const { return loads_; }
  /// Unique among the Models of this process (never 0): the `model` of the handles it makes.
  std::uint64_t id() const { return id_; }
  /// Takes the id of the model this one is a copy of (unpickling), before any body is added.
  void adopt_id(std::uint64_t id);
  int body_index(const std::string& name) const;  ///< −1 for "ground"; throws if unknown
  int coordinate_index(int body, const std::string& coordinate) const;
  /// "body.rz": the name of coordinate `coordinate` (−1: the only one) of a body's joint.
  std::string coordinate_name(int body, int coordinate) const;

  /// Freezes the description into an immutable System.
  std::shared_ptr<const System> compile(Algorithm algorithm) const;

 private:
  void check_body(int body, const char* argument) const;
  /// Throws std::invalid_argument naming the argument unless `b` may be added as body `index`
  /// (bodies 0..index−1 being those before it, their names in index_of_).
  void check_spec(const BodySpec& b, int index) const;
  int resolve_coordinate(int body, int coordinate) const;
  std::uint64_t id_;
  Vec3 gravity_;
  std::vector<BodySpec> bodies_;
  std::unordered_map<std::string, int> index_of_;  // body name -> index
  std::vector<std::vector<CoordinateSpec>> coords_;  // (nbodies) x (ncoords of the joint)
  std::vector<Load> loads_;
  std::vector<Loop> loops_;
  std::vector<Flow> flows_;
  std::vector<ForceElement> elements_;
  std::vector<Shape> shapes_;
  std::vector<Contact> contacts_;
};

}  // namespace rigidfem

#include "rigidfem/model.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "rigidfem/errors.hpp"

namespace rigidfem {

namespace {

std::string num8(double x) { return num(x, 8); }

// `item`, or std::invalid_argument naming `name` if its name is empty or another of `items` has it already.
template <class T>
const T& with_unique_name(const T& item, const std::vector<T>& items, const char* what) {
  if (item.name.empty()) bad("name", std::string("a non-empty name of the ") + what, "''");
  for (const T& other : items)
    if (other.name == item.name)
      bad("name", std::string("a name not used by another ") + what, "'" + item.name + "'");
  return item;
}

// The growth x_k(t) = κ (L(t) − L₀) of the distance between two rfe frames of a link of varying
// length (flows.hpp), with its rates κ L̇ and κ L̈.
class Growth final : public Profile {
 public:
  Growth(ProfilePtr length, double kappa, double length0) : length_(std::move(length)), kappa_(kappa), length0_(length0) {}
  MotionState at(double t) const override {
    const MotionState L = length_->at(t);
    return {kappa_ * (L.q - length0_), kappa_ * L.qd, kappa_ * L.qdd};
  }
  std::string describe() const override { return num8(kappa_) + " (L(t) - " + num8(length0_) + "), L(t) = " + length_->describe(); }

 private:
  ProfilePtr length_;
  double kappa_, length0_;
};

}  // namespace

ProfilePtr growth_profile(ProfilePtr length, double kappa, double length0) {
  return std::make_shared<Growth>(std::move(length), kappa, length0);
}

namespace {

template <class M>
void require_finite(const M& x, const std::string& argument) {
  if (!x.allFinite()) bad(argument, "finite values", "NaN or inf");
}

void check_inertia(const Mat3& I, const std::string& body) {
  const auto arg = [&body] { return "inertia of body '" + body + "'"; };  // built for a message only
  if (!I.allFinite()) bad(arg(), "finite values", "NaN or inf");
  const double scale = I.cwiseAbs().maxCoeff();
  if ((I - I.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) bad(arg(), "a symmetric 3x3 tensor", "an asymmetric one");
  Vec3 l;  // principal moments, ascending
  if (I(0, 1) == 0.0 && I(0, 2) == 0.0 && I(1, 2) == 0.0 && I(1, 0) == 0.0 && I(2, 0) == 0.0 && I(2, 1) == 0.0) {
    l = I.diagonal();  // principal axes already (every rfe of a beam)
    std::sort(l.data(), l.data() + 3);
  } else {
    l = Eigen::SelfAdjointEigenSolver<Mat3>(I, Eigen::EigenvaluesOnly).eigenvalues();
  }
  if (!(l(0) > 0.0)) bad(arg(), "a positive definite tensor (kg·m²)", "principal moments " + num8(l(0)) + ", " + num8(l(1)) + ", " + num8(l(2)));
  // A real body's principal moments satisfy the triangle inequality I_a + I_b >= I_c.
  if (l(0) + l(1) < l(2) * (1.0 - 1e-9))
    bad(arg(), "principal moments satisfying the triangle inequality I1 + I2 >= I3",
        num8(l(0)) + " + " + num8(l(1)) + " < " + num8(l(2)));
}

void check_placement(const Mat4& T, const std::string& argument) {
  require_finite(T, argument);
  const Mat3 R = T.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-9 || R.determinant() < 0.0)
    bad(argument, "a homogeneous transform whose 3x3 block is a rotation", "a non-orthonormal block");
  if ((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-12)
    bad(argument, "last row [0, 0, 0, 1]", "another row");
}

}  // namespace

Joint Joint::make(const std::string& kind, std::vector<Axis> axes) {
  std::sort(axes.begin(), axes.end());  // the book's order x, y, z, φ3, φ2, φ1
  if (std::adjacent_find(axes.begin(), axes.end()) != axes.end())
    bad("coordinates", "each of x, y, z, rz, ry, rx at most once", "a repeated coordinate");
  Joint j;
  j.kind = kind;
  j.axes = std::move(axes);
  j.stiffness.assign(j.axes.size(), 0.0);
  j.rest.assign(j.axes.size(), 0.0);
  j.damping.assign(j.axes.size(), 0.0);
  return j;
}

Mat4 pseudo_inertia(double mass, const Vec3& com, const Mat3& inertia) {
  const Mat3 I_O = inertia + mass * (com.squaredNorm() * Mat3::Identity() - com * com.transpose());
  Mat4 H;
  H.topLeftCorner<3, 3>() = 0.5 * I_O.trace() * Mat3::Identity() - I_O;  // ∫ r rᵀ dm
  H.topRightCorner<3, 1>() = mass * com;
  H.bottomLeftCorner<1, 3>() = mass * com.transpose();
  H(3, 3) = mass;
  return H;
}

Model::Model(const Vec3& gravity) {
  // Ids count up from a random 64-bit start drawn once per process, so that a model unpickled in
  // another process (which keeps its id, and its handles with it) meets no other model's id there.
  static std::atomic<std::uint64_t> models{(std::uint64_t{std::random_device{}()} << 32) ^ std::random_device{}()};
  do id_ = ++models;
  while (id_ == 0);  // 0 marks a handle of unknown origin
  set_gravity(gravity);
}

void Model::adopt_id(std::uint64_t id) {
  if (!bodies_.empty()) bad("id", "an id adopted before the first body is added", "a model with bodies");
  if (id == 0) bad("id", "a nonzero model id", "0");
  id_ = id;
}

void Model::set_gravity(const Vec3& g) {
  require_finite(g, "gravity");
  gravity_ = g;
}

int Model::body_index(const std::string& name) const {
  if (name == "ground") return -1;
  const auto it = index_of_.find(name);
  if (it == index_of_.end()) bad("parent", "the name of a body already in the model or 'ground'", "'" + name + "'");
  return it->second;
}

void Model::check_body(int body, const char* argument) const {
  if (body < 0 || body >= static_cast<int>(bodies_.size()))
    bad(argument, "a body of this model (index 0.." + std::to_string(static_cast<int>(bodies_.size()) - 1) + ")",
        "index " + std::to_string(body));
}

void Model::check_spec(const BodySpec& b, int index) const {
  const std::string& name = b.name;
  if (name.empty() || name == "ground") bad("name", "a non-empty name other than 'ground'", "'" + name + "'");
  if (index_of_.count(name))
    bad("name", "a name not yet used in this model", "duplicate '" + name + "'");
  if (b.parent < -1 || b.parent >= index)
    bad("parent", "a body already in the model or the ground", "index " + std::to_string(b.parent));
  if (!(b.mass > 0.0) || !std::isfinite(b.mass)) bad("mass", "a positive finite mass in kg", num8(b.mass));
  require_finite(b.com, "com");
  check_inertia(b.inertia, name);
  check_placement(b.placement, "placement");
  const Joint& joint = b.joint;
  const int n = joint.ncoords();
  if (static_cast<int>(joint.stiffness.size()) != n || static_cast<int>(joint.rest.size()) != n ||
      static_cast<int>(joint.damping.size()) != n)
    bad("joint", "stiffness, rest and damping with one value per coordinate", "other lengths");
  for (int k = 0; k < n; ++k) {
    if (!(joint.stiffness[k] >= 0.0) || !std::isfinite(joint.stiffness[k]))
      bad("stiffness", "non-negative finite values", num8(joint.stiffness[k]));
    if (!(joint.damping[k] >= 0.0) || !std::isfinite(joint.damping[k]))
      bad("damping", "non-negative finite values", num8(joint.damping[k]));
    if (!std::isfinite(joint.rest[k])) bad("rest", "finite values", num8(joint.rest[k]));
  }
  for (const auto& c : joint.coupled) {
    if (!joint.linear) bad("joint", "coupled coordinates only on a linear joint", "an exact joint");
    // The coupled body may be an earlier body of the same batch: its joint is then not in bodies_ yet,
    // so add_bodies checks the slot against the batch (see there).
    if (c.body < 0 || c.body >= index || c.slot < 0 ||
        (c.body < static_cast<int>(bodies_.size()) && c.slot >= bodies_[c.body].joint.ncoords()))
      bad("joint", "coupled coordinates of bodies already in the model", "body " + std::to_string(c.body));
    if (!c.G.allFinite()) bad("joint", "coupling generators G (4, 4) of finite values", "NaN or inf");
  }
}

Body Model::add_body(const std::string& name, int parent, const Joint& joint, const Mat4& placement, double mass,
                     const Vec3& com, const Mat3& inertia) {
  std::vector<BodySpec> one;
  one.push_back({name, parent, placement, joint, mass, com, inertia});
  return add_bodies(std::move(one)).front();
}

std::vector<Body> Model::add_bodies(std::vector<BodySpec> bodies) {
  const int n0 = static_cast<int>(bodies_.size()), n = static_cast<int>(bodies.size());
  // Check every body, entering its name as it passes (so a batch cannot repeat a name either);
  // a bad one takes the names entered so far out again.
  index_of_.reserve(index_of_.size() + bodies.size());
  int k = 0;
  try {
    for (; k < n; ++k) {
      const BodySpec& b = bodies[k];
      check_spec(b, n0 + k);
      for (const auto& c : b.joint.coupled)
        if (c.body >= n0 && c.slot >= bodies[c.body - n0].joint.ncoords())
          bad("joint", "coupled coordinates of bodies already in the model", "body " + std::to_string(c.body));
      index_of_.emplace(b.name, n0 + k);
    }
  } catch (...) {
    for (int j = 0; j < k; ++j) index_of_.erase(bodies[j].name);
    throw;
  }
  std::vector<Body> handles;
  handles.reserve(bodies.size());
  bodies_.reserve(bodies_.size() + bodies.size());
  coords_.reserve(coords_.size() + bodies.size());
  for (BodySpec& b : bodies) {
    b.inertia = 0.5 * (b.inertia + b.inertia.transpose());
    handles.push_back(Body{static_cast<int>(bodies_.size()), b.name, id_});
    coords_.emplace_back(b.joint.ncoords());
    bodies_.push_back(std::move(b));
  }
  return handles;
}

int Model::coordinate_index(int body, const std::string& coordinate) const {
  check_body(body, "body");
  const Axis a = parse_coordinate(coordinate, "coordinate");
  const auto& axes = bodies_[body].joint.axes;
  const auto it = std::find(axes.begin(), axes.end(), a);
  if (it == axes.end())
    bad("coordinate", "a coordinate of the joint of body '" + bodies_[body].name + "'", "'" + coordinate + "'");
  return static_cast<int>(it - axes.begin());
}

int Model::resolve_coordinate(int body, int coordinate) const {
  check_body(body, "body");
  const int n = bodies_[body].joint.ncoords();
  if (coordinate == -1) {
    if (n != 1)
      bad("coordinate", "a coordinate name, because the joint of body '" + bodies_[body].name + "' has " +
                            std::to_string(n) + " coordinates", "none");
    return 0;
  }
  if (coordinate < 0 || coordinate >= n) bad("coordinate", "0.." + std::to_string(n - 1), std::to_string(coordinate));
  return coordinate;
}

void Model::truncate(int n) {
  if (n < 0 || n > static_cast<int>(bodies_.size()))
    bad("n", "a number of bodies 0.." + std::to_string(bodies_.size()), std::to_string(n));
  for (int p = n; p < static_cast<int>(bodies_.size()); ++p) index_of_.erase(bodies_[p].name);
  bodies_.resize(n);
  coords_.resize(n);
  loads_.erase(std::remove_if(loads_.begin(), loads_.end(), [n](const Load& l) { return l.body >= n; }), loads_.end());
  loops_.erase(std::remove_if(loops_.begin(), loops_.end(), [n](const Loop& l) { return std::max(l.body_a, l.body_b) >= n; }),
               loops_.end());
  flows_.erase(std::remove_if(flows_.begin(), flows_.end(), [n](const Flow& f) { return f.first + f.elements >= n; }),
               flows_.end());
  elements_.erase(std::remove_if(elements_.begin(), elements_.end(),
                                 [n](const ForceElement& e) {
                                   return std::max(e.body_a, e.body_b) >= n ||
                                          std::any_of(e.windings.begin(), e.windings.end(),
                                                      [n](const Winding& w) { return w.body >= n; });
                                 }),
                  elements_.end());
}

std::string Model::coordinate_name(int body, int coordinate) const {
  const int k = resolve_coordinate(body, coordinate);
  return bodies_[body].name + "." + axis_name(bodies_[body].joint.axes[k]);
}

void Model::prescribe(int body, int coordinate, ProfilePtr motion) {
  const int k = resolve_coordinate(body, coordinate);
  if (!motion) bad("motion", "a motion profile (rigidfem.motion.*)", "None");
  if (coords_[body][k].drive)
    bad("coordinate", "a coordinate not prescribed yet (each takes one motion)",
        "'" + coordinate_name(body, k) + "', prescribed already");
  if (!coords_[body][k].arms.empty())
    bad("coordinate", "a coordinate without Maxwell arms (their forces are states of the free motion)",
        "'" + coordinate_name(body, k) + "', which has " + std::to_string(coords_[body][k].arms.size()));
  coords_[body][k].drive = std::move(motion);
}

void Model::add_generalized_force(int body, int coordinate, double value, ForceLaw law) {
  const int k = resolve_coordinate(body, coordinate);
  if (!std::isfinite(value)) bad("force", "a finite generalised force (N or N·m)", num8(value));
  auto& c = coords_[body][k];
  if (law)
    for (const auto& other : c.laws)
      if (&other->info() == &ForceFunction::description()) bad("force", "at most one force law per coordinate", "a second one");
  c.force += value;
  if (law) c.laws.push_back(std::make_shared<ForceFunction>(std::vector<double>{}, std::move(law)));
}

int Model::add_coordinate_law(int body, int coordinate, std::shared_ptr<const CoordinateLaw> law) {
  const int k = resolve_coordinate(body, coordinate);
  if (!law) bad("law", "a law of a joint coordinate (rigidfem.laws)", "None");
  law->validate();
  coords_[body][k].laws.push_back(std::move(law));
  return static_cast<int>(coords_[body][k].laws.size()) - 1;
}

const std::vector<std::shared_ptr<const CoordinateLaw>>& Model::coordinate_laws(int body, int coordinate) const {
  return coords_[body][resolve_coordinate(body, coordinate)].laws;
}

void Model::add_maxwell_arm(int body, int coordinate, const MaxwellArm& arm) {
  const int k = resolve_coordinate(body, coordinate);
  if (!(arm.stiffness > 0.0) || !std::isfinite(arm.stiffness))
    bad("stiffness", "a positive finite arm stiffness (N/m or N·m/rad)", num8(arm.stiffness));
  if (!(arm.tau > 0.0) || !std::isfinite(arm.tau)) bad("tau", "a positive finite relaxation time in s", num8(arm.tau));
  if (coords_[body][k].drive)
    bad("coordinate", "a free coordinate (an arm's force is a state of the free motion)",
        "'" + coordinate_name(body, k) + "', prescribed");
  coords_[body][k].arms.push_back(arm);
}

void Model::add_load(const Load& load) {
  check_body(load.body, "body");
  require_finite(load.point, "point");
  require_finite(load.force, "force");
  require_finite(load.torque, "torque");
  loads_.push_back(load);
}

int Model::add_loop(const Loop& loop) {
  if (loop.body_a < -1 || loop.body_a >= static_cast<int>(bodies_.size())) check_body(loop.body_a, "a");
  if (loop.body_b < -1 || loop.body_b >= static_cast<int>(bodies_.size())) check_body(loop.body_b, "b");
  for (const auto& [F, name] : {std::pair<const Mat4*, const char*>{&loop.frame_a, "frame_a"}, {&loop.frame_b, "frame_b"}}) {
    const Mat3 R = F->topLeftCorner<3, 3>();
    if (!F->allFinite() || (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-9 ||
        R.determinant() < 0.0 || (F->row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 0.0)
      bad(name, "a rigid transformation (4, 4): rotation and translation (rigidfem.transform)", "another matrix");
  }
  if (loop.kind == LoopKind::Distance && !loop.drive && !(loop.length > 0.0 && std::isfinite(loop.length)))
    bad("length", "a positive distance in m", num8(loop.length));
  // each argument first, then how they go together
  if (loop.body_a == loop.body_b) bad("b", "a body other than a (a loop joins two bodies)", "the same body");
  loops_.push_back(with_unique_name(loop, loops_, "loop"));
  return static_cast<int>(loops_.size()) - 1;
}

int Model::add_force_element(const ForceElement& element) {
  if (element.body_a != -1) check_body(element.body_a, "a");  // −1: the ground
  if (element.body_b != -1) check_body(element.body_b, "b");
  if (element.body_a == element.body_b)
    bad("b", "a body other than a (a force element joins two bodies)", "the same body");
  require_finite(element.point_a, "a");
  require_finite(element.point_b, "b");
  if (!element.law) bad("law", "the law of a force element's kind", "none");
  element.law->validate();
  elements_.push_back(with_unique_name(element, elements_, "force element"));
  return static_cast<int>(elements_.size()) - 1;
}

void Model::wind(int element, int body, int coordinate, double radius, double capstan, double smoothing) {
  if (element < 0 || element >= static_cast<int>(elements_.size()))
    bad("element", "a force element's index 0.." + std::to_string(elements_.size()), std::to_string(element));
  ForceElement& E = elements_[element];
  if (!E.law->winds())
    bad("element", "a force element whose law winds on a drum (a Rope)", std::string("a ") + E.law->info().kind);
  if (E.law->profile())
    bad("length", "a constant unstretched length l₀ for a rope wound on a drum (the drum pays it out)", "a profile");
  const int slot = resolve_coordinate(body, coordinate);
  for (const Winding& w : E.windings)
    if (w.body == body && w.slot == slot) bad("element", "a rope not yet wound on this coordinate", "'" + E.name + "'");
  if (!(radius != 0.0 && std::isfinite(radius))) bad("radius", "a non-zero finite radius in m", num8(radius));
  if (!(capstan >= 0.0 && std::isfinite(capstan))) bad("capstan", "a non-negative finite μθ", num8(capstan));
  if (capstan > 0.0 && !(smoothing > 0.0 && std::isfinite(smoothing)))
    bad("smoothing", "a positive finite regularising rate", num8(smoothing));
  E.windings.push_back({body, slot, -1, radius, capstan, smoothing});
}

int Model::add_shape(const Shape& shape) {
  if (shape.body != -1) check_body(shape.body, "body");  // −1: the ground
  require_finite(shape.a, "a");
  require_finite(shape.b, "b");
  switch (shape.kind) {
    case ShapeKind::Sphere:
    case ShapeKind::Capsule:
      if (!(shape.radius > 0.0) || !std::isfinite(shape.radius)) bad("radius", "a positive radius in m", num8(shape.radius));
      break;
    case ShapeKind::Box:
      if (!((shape.h.array() > 0.0).all() && shape.h.allFinite()))
        bad("half_extents", "three positive half-extents in m", num8(shape.h.minCoeff()));
      if (!(shape.R.allFinite() && (shape.R.transpose() * shape.R - Mat3::Identity()).norm() < 1e-9 && shape.R.determinant() > 0.0))
        bad("rotation", "a rotation matrix (orthonormal, determinant 1)", "another matrix");
      break;
    case ShapeKind::HalfSpace:
      if (!(std::abs(shape.n.norm() - 1.0) < 1e-12)) bad("normal", "a unit normal", num8(shape.n.norm()));
      break;
  }
  if (shape.name.empty()) bad("name", "a non-empty name of the shape", "''");
  for (const Shape& other : shapes_)
    if (other.name == shape.name) bad("name", "a name not used by another shape", "'" + shape.name + "'");
  shapes_.push_back(shape);
  return static_cast<int>(shapes_.size()) - 1;
}

int Model::add_contact(const Contact& contact) {
  const int n = static_cast<int>(shapes_.size());
  bool any = false;
  for (const auto& [group, argument] : {std::pair{&contact.shapes_a, "a"}, std::pair{&contact.shapes_b, "b"}}) {
    if (group->empty()) bad(argument, "one shape or more", "none");
    for (const int k : *group)
      if (k < 0 || k >= n) bad(argument, "shapes of this model (index 0.." + std::to_string(n - 1) + ")", std::to_string(k));
  }
  for (const int ia : contact.shapes_a)
    for (const int ib : contact.shapes_b) {
      const Shape &A = shapes_[ia], &B = shapes_[ib];
      const bool plane_a = A.kind == ShapeKind::HalfSpace, plane_b = B.kind == ShapeKind::HalfSpace;
      if (plane_a && plane_b) bad("b", "shapes that can touch those of a (two half-spaces never do)", "'" + B.name + "'");
      if ((A.kind == ShapeKind::Box && !plane_b) || (B.kind == ShapeKind::Box && !plane_a))
        bad("b", "a half-space against a box (a box touches half-spaces only)", "'" + A.name + "' and '" + B.name + "'");
      any = any || A.body != B.body;
    }
  if (!any) bad("b", "shapes on other bodies than a's (shapes on one body never touch)", "the same body");
  if (!contact.law) bad("law", "a contact law", "none");
  contact.law->validate();
  contacts_.push_back(with_unique_name(contact, contacts_, "contact"));
  return static_cast<int>(contacts_.size()) - 1;
}

void Model::add_flow(Flow flow) {
  if (!flow.length) bad("length", "a rigidfem.motion profile L(t) in m", "None");
  const double L0 = flow.length->at(0.0).q;
  if (!(L0 > 0.0 && std::isfinite(L0))) bad("length", "a profile with a positive length L(0) in m", num8(L0));
  const int n = static_cast<int>(bodies_.size());
  if (flow.elements < 1 || flow.first < 0 || flow.first + flow.elements > n - 1)
    bad("elements", "the rfes of a beam of this model", std::to_string(flow.elements) + " from body " + std::to_string(flow.first));
  for (int k = 1; k <= flow.elements; ++k) {
    const int b = flow.first + k;
    const Joint& j = bodies_[b].joint;
    if (bodies_[b].parent != b - 1 || j.linear || j.axes.empty() || j.axes[0] != Axis::X || coords_[b][0].drive ||
        !coords_[b][0].arms.empty())
      bad("beam", "a chain of rfes whose sde joints start with a free x coordinate (built by add_beam)",
          "body '" + bodies_[b].name + "'");
  }
  for (const Flow& other : flows_)
    if (other.first == flow.first) bad("beam", "a beam not given a varying length yet", "'" + bodies_[flow.first].name + "'");
  flow.length0 = L0;
  for (int k = 1; k <= flow.elements; ++k)
    coords_[flow.first + k][0].drive = growth_profile(flow.length, flow.spacing(k), L0);
  flows_.push_back(std::move(flow));
}

}  // namespace rigidfem

#include "rigidfem/model.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "rigidfem/errors.hpp"

namespace rigidfem {

namespace {

std::string num8(double x) { return num(x, 8); }

template <class M>
void require_finite(const M& x, const std::string& argument) {
  if (!x.allFinite()) bad(argument, "finite values", "NaN or inf");
}

void check_inertia(const Mat3& I, const std::string& body) {
  const std::string arg = "inertia of body '" + body + "'";
  require_finite(I, arg);
  const double scale = I.cwiseAbs().maxCoeff();
  if ((I - I.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) bad(arg, "a symmetric 3x3 tensor", "an asymmetric one");
  Eigen::SelfAdjointEigenSolver<Mat3> es(I);
  const Vec3 l = es.eigenvalues();  // ascending
  if (!(l(0) > 0.0)) bad(arg, "a positive definite tensor (kg·m²)", "principal moments " + num8(l(0)) + ", " + num8(l(1)) + ", " + num8(l(2)));
  // A real body's principal moments satisfy the triangle inequality I_a + I_b >= I_c.
  if (l(0) + l(1) < l(2) * (1.0 - 1e-9))
    bad(arg, "principal moments satisfying the triangle inequality I1 + I2 >= I3",
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

Model::Model(const Vec3& gravity) { set_gravity(gravity); }

void Model::set_gravity(const Vec3& g) {
  require_finite(g, "gravity");
  gravity_ = g;
}

int Model::body_index(const std::string& name) const {
  if (name == "ground") return -1;
  for (size_t p = 0; p < bodies_.size(); ++p)
    if (bodies_[p].name == name) return static_cast<int>(p);
  bad("parent", "the name of a body already in the model or 'ground'", "'" + name + "'");
}

void Model::check_body(int body, const char* argument) const {
  if (body < 0 || body >= static_cast<int>(bodies_.size()))
    bad(argument, "a body of this model (index 0.." + std::to_string(static_cast<int>(bodies_.size()) - 1) + ")",
        "index " + std::to_string(body));
}

Body Model::add_body(const std::string& name, int parent, const Joint& joint, const Mat4& placement, double mass,
                     const Vec3& com, const Mat3& inertia) {
  if (name.empty() || name == "ground") bad("name", "a non-empty name other than 'ground'", "'" + name + "'");
  for (const auto& b : bodies_)
    if (b.name == name) bad("name", "a name not yet used in this model", "duplicate '" + name + "'");
  if (parent < -1 || parent >= static_cast<int>(bodies_.size()))
    bad("parent", "a body already in the model or the ground", "index " + std::to_string(parent));
  if (!(mass > 0.0) || !std::isfinite(mass)) bad("mass", "a positive finite mass in kg", num8(mass));
  require_finite(com, "com");
  check_inertia(inertia, name);
  check_placement(placement, "placement");
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
    if (c.body < 0 || c.body >= static_cast<int>(bodies_.size()) || c.slot < 0 ||
        c.slot >= bodies_[c.body].joint.ncoords())
      bad("joint", "coupled coordinates of bodies already in the model", "body " + std::to_string(c.body));
    require_finite(c.G, "coupling generator");
  }
  bodies_.push_back({name, parent, placement, joint, mass, com, 0.5 * (inertia + inertia.transpose())});
  coords_.emplace_back(n);
  return Body{static_cast<int>(bodies_.size()) - 1, name};
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

void Model::prescribe(int body, int coordinate, ProfilePtr motion) {
  const int k = resolve_coordinate(body, coordinate);
  if (!motion) bad("motion", "a motion profile (rigidfem.motion.*)", "None");
  coords_[body][k].drive = std::move(motion);
}

void Model::add_generalized_force(int body, int coordinate, double value, ForceLaw law) {
  const int k = resolve_coordinate(body, coordinate);
  if (!std::isfinite(value)) bad("force", "a finite generalised force (N or N·m)", num8(value));
  auto& c = coords_[body][k];
  c.force += value;
  if (law) {
    if (c.force_law) bad("force", "at most one force law per coordinate", "a second one");
    c.force_law = std::move(law);
  }
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
  if (loop.body_a == loop.body_b) bad("b", "a body other than a (a loop joins two bodies)", "the same body");
  for (const auto& [F, name] : {std::pair<const Mat4*, const char*>{&loop.frame_a, "frame_a"}, {&loop.frame_b, "frame_b"}}) {
    const Mat3 R = F->topLeftCorner<3, 3>();
    if (!F->allFinite() || (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-9 ||
        R.determinant() < 0.0 || (F->row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 0.0)
      bad(name, "a rigid transformation (4, 4): rotation and translation (rigidfem.transform)", "another matrix");
  }
  if (loop.kind == LoopKind::Distance && !loop.drive && !(loop.length > 0.0 && std::isfinite(loop.length)))
    bad("length", "a positive distance in m", num8(loop.length));
  for (const Loop& other : loops_)
    if (other.name == loop.name) bad("name", "a name not used by another loop", "'" + loop.name + "'");
  loops_.push_back(loop);
  return static_cast<int>(loops_.size()) - 1;
}

}  // namespace rigidfem

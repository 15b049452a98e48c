#include "rigidfem/model.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "rigidfem/system.hpp"

namespace rigidfem {

namespace {

std::string num(double x) {
  std::ostringstream o;
  o.precision(8);
  o << x;
  return o.str();
}

[[noreturn]] void bad(const std::string& argument, const std::string& expected, const std::string& got) {
  throw std::invalid_argument(argument + ": expected " + expected + ", got " + got);
}

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
  if (!(l(0) > 0.0)) bad(arg, "a positive definite tensor (kg·m²)", "principal moments " + num(l(0)) + ", " + num(l(1)) + ", " + num(l(2)));
  // A real body's principal moments satisfy the triangle inequality I_a + I_b >= I_c.
  if (l(0) + l(1) < l(2) * (1.0 - 1e-9))
    bad(arg, "principal moments satisfying the triangle inequality I1 + I2 >= I3",
        num(l(0)) + " + " + num(l(1)) + " < " + num(l(2)));
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

Axis parse_axis(const std::string& name, bool rotation, const std::string& argument) {
  if (name == "x") return rotation ? Axis::RX : Axis::X;
  if (name == "y") return rotation ? Axis::RY : Axis::Y;
  if (name == "z") return rotation ? Axis::RZ : Axis::Z;
  bad(argument, "'x', 'y' or 'z'", "'" + name + "'");
}

Axis parse_coordinate(const std::string& name, const std::string& argument) {
  static const char* names[6][2] = {{"x", "x"}, {"y", "y"}, {"z", "z"}, {"rz", "phi3"}, {"ry", "phi2"}, {"rx", "phi1"}};
  for (int k = 0; k < 6; ++k)
    if (name == names[k][0] || name == names[k][1]) return static_cast<Axis>(k);
  bad(argument, "one of 'x', 'y', 'z', 'rz', 'ry', 'rx' (or 'phi3', 'phi2', 'phi1')", "'" + name + "'");
}

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
  if (!(mass > 0.0) || !std::isfinite(mass)) bad("mass", "a positive finite mass in kg", num(mass));
  require_finite(com, "com");
  check_inertia(inertia, name);
  check_placement(placement, "placement");
  const int n = joint.ncoords();
  if (static_cast<int>(joint.stiffness.size()) != n || static_cast<int>(joint.rest.size()) != n ||
      static_cast<int>(joint.damping.size()) != n)
    bad("joint", "stiffness, rest and damping with one value per coordinate", "other lengths");
  for (int k = 0; k < n; ++k) {
    if (!(joint.stiffness[k] >= 0.0) || !std::isfinite(joint.stiffness[k]))
      bad("stiffness", "non-negative finite values", num(joint.stiffness[k]));
    if (!(joint.damping[k] >= 0.0) || !std::isfinite(joint.damping[k]))
      bad("damping", "non-negative finite values", num(joint.damping[k]));
    if (!std::isfinite(joint.rest[k])) bad("rest", "finite values", num(joint.rest[k]));
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
  if (!std::isfinite(value)) bad("force", "a finite generalised force (N or N·m)", num(value));
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

std::shared_ptr<const System> Model::compile(Algorithm algorithm) const {
  if (bodies_.empty()) bad("model", "at least one body before compile()", "an empty model");
  auto sys = std::make_shared<System>();
  System& s = *sys;
  s.nbodies = static_cast<int>(bodies_.size());
  s.gravity = gravity_;
  s.loads = loads_;
  s.children.resize(s.nbodies);
  s.coord_start.push_back(0);
  for (int p = 0; p < s.nbodies; ++p) {
    const BodySpec& b = bodies_[p];
    s.body_names.push_back(b.name);
    s.parent.push_back(b.parent);  // parent[p] < p: bodies are added after their parents
    if (b.parent >= 0) s.children[b.parent].push_back(p);
    s.B.push_back(b.placement);
    s.H.push_back(pseudo_inertia(b.mass, b.com, b.inertia));
    s.mass.push_back(b.mass);
    s.com.push_back(b.com);
    s.inertia.push_back(b.inertia);
    s.joint.push_back(b.joint);
    for (int k = 0; k < b.joint.ncoords(); ++k) {
      Coordinate c;
      c.body = p;
      c.slot = k;
      c.axis = b.joint.axes[k];
      c.stiffness = b.joint.stiffness[k];
      c.rest = b.joint.rest[k];
      c.damping = b.joint.damping[k];
      c.force = coords_[p][k].force;
      c.force_law = coords_[p][k].force_law;
      c.drive = coords_[p][k].drive;
      c.name = b.name + "." + axis_name(c.axis);
      const int index = static_cast<int>(s.coords.size());
      if (c.drive) {
        c.drive_index = static_cast<int>(s.drive_coords.size());
        s.drive_coords.push_back(index);
      } else {
        c.free_index = static_cast<int>(s.free_coords.size());
        s.free_coords.push_back(index);
      }
      s.coords.push_back(std::move(c));
    }
    s.coord_start.push_back(static_cast<int>(s.coords.size()));
  }
  // Uses: own coordinates with their elementary generators, then the coupled ones.
  for (int p = 0; p < s.nbodies; ++p) {
    s.use_start.push_back(static_cast<int>(s.use_coord.size()));
    for (int i = s.coord_start[p]; i < s.coord_start[p + 1]; ++i) {
      s.use_coord.push_back(i);
      s.use_G.push_back(generator(s.coords[i].axis));
    }
    for (const auto& c : s.joint[p].coupled) {
      s.use_coord.push_back(s.coord_start[c.body] + c.slot);
      s.use_G.push_back(c.G);
    }
    s.max_uses = std::max(s.max_uses, static_cast<int>(s.use_coord.size()) - s.use_start.back());
  }
  s.use_start.push_back(static_cast<int>(s.use_coord.size()));
  for (int p = 0; p < s.nbodies; ++p) {
    const auto& ax = s.joint[p].axes;
    auto has = [&](Axis a) { return std::find(ax.begin(), ax.end(), a) != ax.end(); };
    if (!s.joint[p].linear && has(Axis::RZ) && has(Axis::RY) && has(Axis::RX))
      s.zyx_pitch.push_back(s.coord_start[p] + static_cast<int>(std::find(ax.begin(), ax.end(), Axis::RY) - ax.begin()));
  }
  s.nuses = static_cast<int>(s.use_coord.size());
  s.nc = static_cast<int>(s.coords.size());
  s.nq = static_cast<int>(s.free_coords.size());
  const bool any_linear = std::any_of(s.joint.begin(), s.joint.end(), [](const Joint& j) { return j.linear; });
  s.algorithm = any_linear ? Algorithm::Lagrange : algorithm;
  s.np = static_cast<int>(s.drive_coords.size());
  return sys;
}

std::vector<std::string> System::coordinate_names() const {
  std::vector<std::string> names;
  for (int i : free_coords) names.push_back(coords[i].name);
  return names;
}

std::vector<std::string> System::prescribed_names() const {
  std::vector<std::string> names;
  for (int i : drive_coords) names.push_back(coords[i].name);
  return names;
}

Data::Data(const System& s)
    : qa(VecX::Zero(s.nc)),
      qda(VecX::Zero(s.nc)),
      qdda(VecX::Zero(s.nc)),
      T(s.nbodies, Mat4::Identity()),
      Td(s.nbodies, Mat4::Zero()),
      Tdd(s.nbodies, Mat4::Zero()),
      U(s.nuses, Mat4::Zero()),
      X(s.max_uses, Mat4::Zero()),
      Hbar(s.nbodies, Mat4::Zero()),
      Wbar(s.nbodies, Mat4::Zero()),
      Zbar(s.nbodies, Mat4::Zero()),
      f(VecX::Zero(s.nq)),
      qdd(VecX::Zero(s.nq)),
      tau(VecX::Zero(s.np)),
      axes(s.nuses, Vec6::Zero()),
      v(s.nbodies, Vec6::Zero()),
      c(s.nbodies, Vec6::Zero()),
      a(s.nbodies, Vec6::Zero()),
      sf(s.nbodies, Vec6::Zero()),
      pA(s.nbodies, Vec6::Zero()),
      I(s.nbodies, Mat6::Zero()),
      IA(s.nbodies, Mat6::Zero()),
      fext(s.nbodies, Vec6::Zero()),
      U6(s.nbodies),
      Dinv(s.nbodies),
      u(s.nbodies) {}

}  // namespace rigidfem

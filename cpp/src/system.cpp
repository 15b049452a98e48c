// Model::compile, which freezes a Model into a System, and the System's workspace.
#include "rigidfem/system.hpp"

#include <algorithm>
#include <stdexcept>

#include "rigidfem/errors.hpp"

namespace rigidfem {

std::shared_ptr<const System> Model::compile(Algorithm algorithm) const {
  if (bodies_.empty()) bad("model", "at least one body before compile()", "an empty model");
  auto sys = std::make_shared<System>();
  System& s = *sys;
  s.nbodies = static_cast<int>(bodies_.size());
  s.gravity = gravity_;
  s.loads = loads_;
  s.loops = loops_;
  s.flows = flows_;
  s.elements = elements_;
  s.shapes = shapes_;
  s.contacts = contacts_;
  s.loop_row.push_back(0);
  for (const Loop& L : loops_) s.loop_row.push_back(s.loop_row.back() + loop_rows(L.kind));
  s.nl = s.loop_row.back();
  // One allocation per table (a beam of 10⁵ rfes compiles in O(n) without regrowing them).
  const std::size_t nb = bodies_.size();
  s.body_names.reserve(nb);
  s.parent.reserve(nb);
  s.B.reserve(nb);
  s.shift_only.reserve(nb);
  s.H.reserve(nb);
  s.mass.reserve(nb);
  s.com.reserve(nb);
  s.inertia.reserve(nb);
  s.joint.reserve(nb);
  s.coord_start.reserve(nb + 1);
  s.use_start.reserve(nb + 1);
  s.coord_start.push_back(0);
  for (int p = 0; p < s.nbodies; ++p) {
    const BodySpec& b = bodies_[p];
    s.body_names.push_back(b.name);
    s.parent.push_back(b.parent);  // parent[p] < p: bodies are added after their parents
    s.B.push_back(b.placement);
    s.shift_only.push_back(b.placement.topLeftCorner<3, 3>() == Mat3::Identity());
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
      c.spring = {b.joint.stiffness[k], b.joint.rest[k], b.joint.damping[k], coords_[p][k].force};
      c.laws = coords_[p][k].laws;
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
      for (const MaxwellArm& a : coords_[p][k].arms) s.arms.push_back({index, c.free_index, a.stiffness, a.tau});
      s.coords.push_back(std::move(c));
    }
    s.coord_start.push_back(static_cast<int>(s.coords.size()));
  }
  s.nz = static_cast<int>(s.arms.size());
  // Uses: own coordinates with their elementary generators, then the coupled ones.
  for (int p = 0; p < s.nbodies; ++p) {
    s.use_start.push_back(static_cast<int>(s.use_coord.size()));
    auto use = [&s](int i, const Mat4& G) {
      s.use_coord.push_back(i);
      s.use_axis.push_back(s.coords[i].axis);
      s.use_G.push_back(G);
      s.use_q.push_back(s.coords[i].free_index);
      s.use_drive.push_back(s.coords[i].drive_index);
    };
    for (int i = s.coord_start[p]; i < s.coord_start[p + 1]; ++i) use(i, generator(s.coords[i].axis));
    for (const auto& c : s.joint[p].coupled) use(s.coord_start[c.body] + c.slot, c.G);
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
  // Free coordinates per body: contiguous in q, numbered in body order.
  s.q_index.assign(s.nbodies, 0);
  s.nq_of.assign(s.nbodies, 0);
  for (int p = 0, k = 0; p < s.nbodies; ++p) {
    s.q_index[p] = k;
    for (int i = s.coord_start[p]; i < s.coord_start[p + 1]; ++i)
      if (s.coords[i].free_index >= 0) ++s.nq_of[p], ++k;
  }
  for (int i : s.free_coords) s.q_use.push_back(own_use(s, i));
  // A ball: three free coordinates, all rotations, and no translation after a rotation (prescribed ones before,
  // as a flow's x: the book's order), so that every free axis passes through the frame's final origin.
  s.ball.assign(s.nbodies, 0);
  for (int p = 0; p < s.nbodies; ++p) {
    bool ball = s.nq_of[p] == 3 && !s.joint[p].linear, turned = false;
    for (int u = s.use_start[p]; ball && u < s.use_start[p + 1]; ++u) {
      if (is_rotation(s.use_axis[u]))
        turned = true;
      else
        ball = !turned && s.use_q[u] < 0;  // a prescribed translation before the rotations
    }
    s.ball[p] = ball;
  }
  // ropes wound on drums and sheaves: each winding's coordinate, and on it the windings it takes
  for (int k = 0; k < static_cast<int>(s.elements.size()); ++k)
    for (int j = 0; j < static_cast<int>(s.elements[k].windings.size()); ++j) {
      Winding& w = s.elements[k].windings[j];
      w.coord = s.coord_start[w.body] + w.slot;
      s.coords[w.coord].windings.push_back({k, j});
    }
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
      arm_force(VecX::Zero(s.nc)),
      g(VecX::Zero(s.nl)),
      gd(VecX::Zero(s.nl)),
      gamma(VecX::Zero(s.nl)),
      G(MatX::Zero(s.nl, s.nc)),
      lambda(VecX::Zero(s.nl)),
      Gfree(MatX::Zero(s.nl, s.nq)),
      Y(MatX::Zero(s.nq, s.nl)),
      GY(MatX::Zero(s.nl, s.nl)),
      loop_rhs(VecX::Zero(s.nl)),
      loop_col(VecX::Zero(s.nq)),
      loop_c(VecX::Zero(s.nl)),
      loop_eigen(s.nl),
      axes(s.nuses, Vec6::Zero()),
      v(s.nbodies, Vec6::Zero()),
      c(s.nbodies, Vec6::Zero()),
      a(s.nbodies, Vec6::Zero()),
      sf(s.nbodies, Vec6::Zero()),
      pA(s.nbodies, Vec6::Zero()),
      I(s.nbodies, Mat6::Zero()),
      IA(s.nbodies, Mat6::Zero()),
      fext(s.nbodies, Vec6::Zero()),
      S(s.nbodies),
      U6(s.nbodies),
      Dinv(s.nbodies),
      u(s.nbodies),
      H(s.H),
      mass(s.mass),
      com(s.com),
      inertia(s.inertia),
      spring_scale(VecX::Ones(s.nc)),
      flow(s.flows.size()) {}

void check_body(const System& sys, int body, const std::string& argument, bool ground_allowed) {
  if (body < (ground_allowed ? -1 : 0) || body >= sys.nbodies)
    bad(argument, "a body of this system (index " + std::string(ground_allowed ? "-1" : "0") + ".." +
                      std::to_string(sys.nbodies - 1) + ")",
        "index " + std::to_string(body));
}

void check_data(const System& sys, const Data& d) {
  if (static_cast<int>(d.T.size()) != sys.nbodies || d.qa.size() != sys.nc || d.f.size() != sys.nq ||
      d.qdd.size() != sys.nq || d.tau.size() != sys.np)
    throw std::invalid_argument(
        "data: expected a workspace made by this system's make_data(), got one of another system");
}

void check_state(const System& sys, const Data& d) {
  check_data(sys, d);
  if (!d.state_ok)
    throw std::invalid_argument(
        "data: expected a workspace with a state, got one whose last set_state raised (call set_state again)");
}

}  // namespace rigidfem

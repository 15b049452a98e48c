#include "rigidfem/derivatives.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>
#include <vector>

namespace rigidfem {

namespace {

// δI x for δI = s ×* I − I s ×m (the inertia turned by the twist s), without forming δI.
Vec6 turned_inertia_times(const Vec6& s, const Mat6& I, const Vec6& x) { return crossf(s, I * x) - I * crossm(s, x); }

// ∂Q/∂x of a scalar force law Q(t, q_i, q̇_i) by a central difference in x (q or q̇).
double law_derivative(const Coordinate& c, const Data& d, int i, bool rate) {
  double q = d.qa(i), qd = d.qda(i);
  double& x = rate ? qd : q;
  const double x0 = x, h = difference_step(x0);
  x = x0 + h;
  const double up = c.force_law(d.t, q, qd);
  x = x0 - h;
  const double down = c.force_law(d.t, q, qd);
  return (up - down) / (2.0 * h);
}

// Tangents of the RNEA quantities along one direction (one coordinate's q or q̇).
struct Tangent {
  explicit Tangent(const System& sys) : inside(sys.nbodies), v(sys.nbodies), a(sys.nbodies), f(sys.nbodies) {}
  std::vector<char> inside;  // body in the subtree carried by the coordinate
  std::vector<Vec6> v, a, f;  // δv_p, δa_p, δf̄_p
};

// A load on a body (the load's own point moving with it: the geometric term of the tangent).
struct BodyLoad {
  int body;
  bool follower;
  AppliedLoad load;
};

// δ(r, ṙ) of a point x (global) of body b along the direction of the tangent w: a point carried
// by the coordinate moves by δx = s_v + s_ω × x (position), and its velocity ṙ = v_O + ω × x
// changes by δv_O + δω × x + ω × δx.
std::pair<Vec3, Vec3> point_tangent(const Data& d, const Tangent& w, int b, const Vec3& x, const Vec6& s,
                                    bool position) {
  if (b < 0 || !w.inside[b]) return {Vec3::Zero(), Vec3::Zero()};
  const Vec3 dx = position ? Vec3(s.tail<3>() + s.head<3>().cross(x)) : Vec3::Zero();
  return {dx, w.v[b].tail<3>() + w.v[b].head<3>().cross(x) + d.v[b].head<3>().cross(dx)};
}

// The change of a force element's force f_B = F e = −f_A along the tangent (its points' motion
// under the fixed force is the geometric term of BodyLoad): with δd = δr_B − δr_A,
//   δe = (1 − e eᵀ) δd / l,  δl = e·δd,  δl̇ = δe·ḋ + e·δḋ,  δf_B = (F_l δl + F_l̇ δl̇) e + F δe,
// applied at r_B and r_A as −δf_ext.
void element_tangent(const System& sys, const Data& d, const ForceElement& E, const ElementState& st, const Vec6& s,
                     bool position, Tangent& w) {
  const auto [dxb, dvb] = point_tangent(d, w, E.body_b, st.xb, s, position);
  const auto [dxa, dva] = point_tangent(d, w, E.body_a, st.xa, s, position);
  const Vec3 dd = dxb - dxa, ddd = dvb - dva;
  if (dd.isZero(0.0) && ddd.isZero(0.0)) return;
  const Vec3 de = (dd - st.e * st.e.dot(dd)) / st.l;
  const double dl = st.e.dot(dd), dld = de.dot(st.vb - st.va) + st.e.dot(ddd);
  const auto [Fl, Fld] = E.law->derivatives(d.t, st.l, st.ld, d.load_factor);
  const Vec3 df = (Fl * dl + Fld * dld) * st.e + st.F * de;
  for (const auto& [body, x, f] : {std::tuple<int, Vec3, Vec3>{E.body_b, st.xb, df}, {E.body_a, st.xa, -df}}) {
    if (body < 0) continue;
    w.f[body].head<3>() -= x.cross(f);
    w.f[body].tail<3>() -= f;
  }
}

// The change of the loads of the flowing material on one rfe (flow_loads) along the tangent (the
// motion of their points under fixed forces is the geometric term of BodyLoad): its axis turns,
// δe = s_ω × e when carried (position), and its angular velocity changes by δω;
//   δF_C = −m (2 α (δω × e + ω × δe) + β δe) at x_C,  δF_turn = −ρA α² (δe − δe_prev) at the origin.
void flow_tangent(const FlowTerm& f, const Vec6& s, bool position, Tangent& w) {
  const bool carried = w.inside[f.body];
  const bool prev_carried = position && f.prev >= 0 && w.inside[f.prev];
  if (!carried && !prev_carried) return;
  const Vec3 de = position && carried ? Vec3(s.head<3>().cross(f.e)) : Vec3::Zero();
  const Vec3 de_prev = prev_carried ? Vec3(s.head<3>().cross(f.e_prev)) : Vec3::Zero();
  const Vec3 dw = carried ? Vec3(w.v[f.body].head<3>()) : Vec3::Zero();
  const Vec3 dF_c = -f.m * (2.0 * f.alpha * (dw.cross(f.e) + f.omega.cross(de)) + f.beta * de);
  const Vec3 dF_turn = -f.rhoA * f.alpha * f.alpha * (de - de_prev);
  w.f[f.body].head<3>() -= f.xc.cross(dF_c) + f.origin.cross(dF_turn);
  w.f[f.body].tail<3>() -= dF_c + dF_turn;
}

// Column ∂r/∂q_j (position) or ∂r/∂q̇_j (rate) for the coordinate j with use uj on body bj,
// into col (nq). Only the bodies carried by q_j (bj and its subtree) have tangents:
//   position: the later axes turn, δs_u = s_j ×m s_u, and so do inertias and follower loads;
//   rate:     δq̇_j = 1, so δv gains s_j from the use uj on and δc gains v ×m s_j there.
// Then δc = Σ (δv ×m s_u + v ×m δs_u) q̇_u, δv = Σ δs_u q̇_u, δa_p = δa_λ + δc + Σ δs_u q̈_u,
// δf_p = δI a + I δa + δv ×* I v + v ×* (δI v + I δv) − δf_ext, summed over subtrees, and
// δr_i = δs_iᵀ f̄_b + s_iᵀ δf̄_b.
void tangent_column(const System& sys, const Data& d, const std::vector<BodyLoad>& loads,
                    const std::vector<ElementState>& elements, const std::vector<FlowTerm>& flows, int uj, int bj,
                    bool position, Tangent& w, Eigen::Ref<VecX> col) {
  const Vec6& s = d.axes[uj];
  auto turned = [&](int p, int u) { return position && w.inside[p] && (p != bj || u > uj); };
  for (int p = 0; p < sys.nbodies; ++p) {
    w.inside[p] = p == bj || (p > bj && sys.parent[p] >= 0 && w.inside[sys.parent[p]]);  // parent[p] < p
    if (!w.inside[p]) {
      w.f[p].setZero();
      continue;
    }
    const int lam = sys.parent[p];
    Vec6 v = lam >= 0 ? d.v[lam] : Vec6::Zero();
    Vec6 dv = p == bj ? Vec6::Zero() : w.v[lam];
    Vec6 da = p == bj ? Vec6::Zero() : w.a[lam];
    for (int u = sys.use_start[p]; u < sys.use_start[p + 1]; ++u) {
      const int i = sys.use_coord[u];
      const double qd = d.qda(i);
      const Vec6 ds = turned(p, u) ? crossm(s, d.axes[u]) : Vec6::Zero();
      da += (crossm(dv, d.axes[u]) + crossm(v, ds)) * qd + ds * d.qdda(i);
      dv += ds * qd;
      if (!position && u == uj) {
        da += crossm(v, d.axes[u]);
        dv += d.axes[u];
      }
      v += d.axes[u] * qd;
    }
    const Mat6& I = d.I[p];
    w.v[p] = dv;
    w.a[p] = da;
    w.f[p] = I * da + crossf(dv, I * d.v[p]) + crossf(d.v[p], I * dv);
    if (position) w.f[p] += turned_inertia_times(s, I, d.a[p]) + crossf(d.v[p], turned_inertia_times(s, I, d.v[p]));
  }
  // Loads on carried bodies: a point fixed in the body moves with velocity v_s + ω_s × x;
  // a follower load turns with the body, δf = s ×* f.
  for (std::size_t k = 0; position && k < loads.size(); ++k) {
    const BodyLoad& L = loads[k];
    if (!w.inside[L.body]) continue;
    const AppliedLoad& l = L.load;
    if (L.follower) {
      Vec6 fl;
      fl << l.x.cross(l.F) + l.tau, l.F;
      w.f[L.body] -= crossf(s, fl);
    } else {
      const Vec3 dx = s.tail<3>() + s.head<3>().cross(l.x);
      w.f[L.body].head<3>() -= dx.cross(l.F);
    }
  }
  for (std::size_t k = 0; k < elements.size(); ++k) element_tangent(sys, d, sys.elements[k], elements[k], s, position, w);
  for (const FlowTerm& f : flows) flow_tangent(f, s, position, w);
  accumulate_subtrees(sys, w.f);
  for (int k = 0; k < sys.nq; ++k) {
    const int b = sys.coords[sys.free_coords[k]].body, u = sys.q_use[k];
    col(k) = d.axes[u].dot(w.f[b]) + (turned(b, u) ? crossm(s, d.axes[u]).dot(d.sf[b]) : 0.0);
  }
}

}  // namespace

std::pair<MatX, MatX> rnea_derivatives(const System& sys, Data& d) {
  spatial_kinematics(sys, d);
  rnea_pass(sys, d);
  // The loads (their geometric term) and the states of the elements and flowing rfes whose forces
  // change with the state.
  std::vector<BodyLoad> loads;
  for_each_body_load(sys, d, true, [&](int body, const AppliedLoad& a, bool follower) {
    loads.push_back({body, follower, a});
  });
  std::vector<ElementState> elements;
  for (const ForceElement& E : sys.elements) elements.push_back(element_state(d, E, true));
  std::vector<FlowTerm> flows;
  for_each_flow_term(sys, d, true, [&](const FlowTerm& f) { flows.push_back(f); });
  MatX dq(sys.nq, sys.nq), dqd(sys.nq, sys.nq);
  Tangent w(sys);
  for (int j = 0; j < sys.nq; ++j) {
    const int i = sys.free_coords[j], b = sys.coords[i].body, u = sys.q_use[j];
    interruption_point();
    tangent_column(sys, d, loads, elements, flows, u, b, true, w, dq.col(j));
    tangent_column(sys, d, loads, elements, flows, u, b, false, w, dqd.col(j));
    // −∂Q_j/∂(q_j, q̇_j) of the coordinate's own spring, damper and force law.
    const Coordinate& c = sys.coords[i];
    dq(j, j) += d.spring_scale(i) * c.stiffness;
    dqd(j, j) += d.spring_scale(i) * c.damping;
    if (c.force_law) {
      dq(j, j) -= d.load_factor * law_derivative(c, d, i, false);
      dqd(j, j) -= d.load_factor * law_derivative(c, d, i, true);
    }
  }
  return {dq, dqd};
}

}  // namespace rigidfem

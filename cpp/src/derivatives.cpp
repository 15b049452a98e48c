#include "rigidfem/derivatives.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

namespace rigidfem {

// (In a named namespace: ResidualTranspose::Prepared, declared in a header, holds them; see LoadTerms.)
namespace detail {

struct BodyLoad {
  int body;
  bool follower;
  AppliedLoad load;
};

}  // namespace detail

namespace {

using detail::BodyLoad;

// Tangents of the RNEA quantities along one direction (one coordinate's q or q̇, or any (δq, δq̇, δq̈)).
struct Tangent {
  explicit Tangent(const System& sys)
      : inside(sys.nbodies), W(sys.nbodies, Vec6::Zero()), v(sys.nbodies, Vec6::Zero()), a(sys.nbodies),
        f(sys.nbodies), dq(VecX::Zero(sys.nq)), dqd(VecX::Zero(sys.nq)), dQ(VecX::Zero(sys.nq)) {}
  /// δf̄_p = I δa + δv ×* I v + v ×* I δv + δI a + v ×* δI v of body p (velocity v, acceleration a) with its inertia
  /// turned by the twist Wp (δI x = Wp ×* I x − I (Wp ×m x)), as two products with I:
  ///   δf̄_p = I (δa − Wp ×m a) + δv ×* I v + Wp ×* I a + v ×* (I (δv − Wp ×m v) + Wp ×* I v).
  static Vec6 body_force(const Data& d, int p, const Vec6& Wp, const Vec6& dv, const Vec6& da) {
    const Mat6& I = d.I[p];
    const Vec6& vp = d.v[p];
    const Vec6 Iv = I * vp;
    return I * (da - crossm(Wp, d.a[p])) + crossf(dv, Iv) + crossf(Wp, I * d.a[p]) +
           crossf(vp, I * (dv - crossm(Wp, vp)) + crossf(Wp, Iv));
  }
  std::vector<char> inside;  // body moved by the direction (its frame, or its velocity)
  std::vector<Vec6> W;       // the twist δT_p T_p⁻¹ that carries body p's frame (zero: it stays)
  std::vector<Vec6> v, a, f;  // δv_p, δa_p, δf̄_p (v zero for a body the direction leaves)
  VecX dq, dqd;  // the direction's (δq, δq̇) (nq): the drums' δφ of the ropes wound on them
  VecX dQ;       // δQ of the free coordinates' generalised forces outside the RNEA (a drum's r δP)
};

// A load on a body (the load's own point moving with it: the geometric term of the tangent).

// δ(r, ṙ) of a point x (global) of body b along the direction of the tangent w: a point of a body carried by
// the twist W_b moves by δx = W_v + W_ω × x, and its velocity ṙ = v_O + ω × x changes by δv_O + δω × x + ω × δx.
std::pair<Vec3, Vec3> point_tangent(const Data& d, const Tangent& w, int b, const Vec3& x) {
  if (b < 0 || !w.inside[b]) return {Vec3::Zero(), Vec3::Zero()};
  const Vec6& W = w.W[b];
  const Vec3 dx = W.tail<3>() + W.head<3>().cross(x);
  return {dx, w.v[b].tail<3>() + w.v[b].head<3>().cross(x) + d.v[b].head<3>().cross(dx)};
}

// The change of a force element's force f_B = F e = −f_A along the tangent (its points' motion
// under the fixed force is the geometric term of BodyLoad): with δd = δr_B − δr_A,
//   δe = (1 − e eᵀ) δd / l,  δl = e·δd,  δl̇ = δe·ḋ + e·δḋ,  δf_B = (F_l δl + F_l̇ δl̇ + F_s δs + F_ṡ δṡ) e + F δe,
// applied at r_B and r_A as −δf_ext. A rope wound on free coordinates q_k (drums, a sheave's slip: δs = Σ r_k δq_k)
// changes each one's r_k P c_k by r_k (c_k δP + P c_k' δq̇_k), δP = P_l δl + P_l̇ δl̇ + P_s δs + P_ṡ δṡ + ½ λ μ g·δd,
// into w.dQ, and a heavy one's weights by δw_B = ½ λ μ δs g = −δw_A (kinematics.hpp: ElementState).
void element_tangent(const System& sys, const Data& d, const ForceElement& E, const ElementState& st, Tangent& w) {
  const auto [dxb, dvb] = point_tangent(d, w, E.body_b, st.xb);
  const auto [dxa, dva] = point_tangent(d, w, E.body_a, st.xa);
  const Vec3 dd = dxb - dxa, ddd = dvb - dva;
  double ds = 0.0, dsd = 0.0;
  bool wound_moves = false;
  for (const Winding& wi : E.windings)
    if (const int k = sys.coords[wi.coord].free_index; k >= 0) {
      ds += wi.radius * w.dq(k), dsd += wi.radius * w.dqd(k);
      wound_moves = wound_moves || w.dq(k) != 0.0 || w.dqd(k) != 0.0;
    }
  if (dd.isZero(0.0) && ddd.isZero(0.0) && !wound_moves) return;
  const Vec3 de = (dd - st.e * st.e.dot(dd)) / st.l;
  const double dl = st.e.dot(dd), dld = de.dot(st.vb - st.va) + st.e.dot(ddd);
  const ExtensionDerivatives F = E.law->derivatives(d.t, st.extension(), d.load_factor);
  const Vec3 g_half = 0.5 * d.load_factor * E.law->span_mass_rate() * sys.gravity;  // ½ λ μ g
  if (!E.windings.empty()) {
    const ExtensionDerivatives P = E.law->pull_derivatives(d.t, st.extension());
    const double dP = P.l * dl + P.ld * dld + P.s * ds + P.sd * dsd + g_half.dot(dd);
    for (const Winding& wi : E.windings)
      if (const int k = sys.coords[wi.coord].free_index; k >= 0) {
        const auto [c, dc] = wi.factor(d.qda(wi.coord));
        w.dQ(k) += wi.radius * (c * dP + st.P * dc * w.dqd(k));
      }
  }
  const Vec3 df = (F.l * dl + F.ld * dld + F.s * ds + F.sd * dsd) * st.e + st.F * de + ds * g_half;
  for (const auto& [body, x, f] : {std::tuple<int, Vec3, Vec3>{E.body_b, st.xb, df}, {E.body_a, st.xa, -df}}) {
    if (body < 0) continue;
    w.f[body].head<3>() -= x.cross(f);
    w.f[body].tail<3>() -= f;
  }
}

// A contact's force f on body b (−f on a) at the contact point x_c, along the tangent: its wrench on b about the
// origin changes by J ε (contact_jacobian, ε = (W_a, δv_a, W_b, δv_b)), of which loads_tangent, moving the loads'
// points with their bodies, took −δx_b × f on b and δx_a × f on a (δx_k = W_v + W_ω × x_c): the rest here.
void contact_tangent(const ContactForce& c, const Eigen::Matrix<double, 6, 24>& J, Tangent& w) {
  Eigen::Matrix<double, 24, 1> eps = Eigen::Matrix<double, 24, 1>::Zero();
  const bool moves_a = c.body_a >= 0 && w.inside[c.body_a], moves_b = c.body_b >= 0 && w.inside[c.body_b];
  if (!moves_a && !moves_b) return;
  if (moves_a) eps << w.W[c.body_a], w.v[c.body_a], Vec6::Zero(), Vec6::Zero();
  if (moves_b) eps.tail<12>() << w.W[c.body_b], w.v[c.body_b];
  const Vec6 dwrench = J * eps;
  const auto moved = [&](bool moves, int k) {
    return moves ? Vec3(w.W[k].tail<3>() + w.W[k].head<3>().cross(c.x)) : Vec3::Zero();
  };
  if (c.body_b >= 0) {
    w.f[c.body_b] -= dwrench;
    w.f[c.body_b].head<3>() += moved(moves_b, c.body_b).cross(c.f);
  }
  if (c.body_a >= 0) {
    w.f[c.body_a] += dwrench;
    w.f[c.body_a].head<3>() -= moved(moves_a, c.body_a).cross(c.f);
  }
}

// The change of the loads of the flowing material on one rfe (flow_loads) along the tangent (the
// motion of their points under fixed forces is the geometric term of BodyLoad): its axis turns with the
// rfe's twist, δe = W_ω × e, and its angular velocity changes by δω;
//   δF_C = −m (2 α (δω × e + ω × δe) + β δe) at x_C,  δF_turn = −ρA α² (δe − δe_prev) at the origin.
void flow_tangent(const FlowTerm& f, Tangent& w) {
  const bool carried = w.inside[f.body];
  const bool prev_carried = f.prev >= 0 && w.inside[f.prev];
  if (!carried && !prev_carried) return;
  const Vec3 de = carried ? Vec3(w.W[f.body].head<3>().cross(f.e)) : Vec3::Zero();
  const Vec3 de_prev = prev_carried ? Vec3(w.W[f.prev].head<3>().cross(f.e_prev)) : Vec3::Zero();
  const Vec3 dw = carried ? Vec3(w.v[f.body].head<3>()) : Vec3::Zero();
  const Vec3 dF_c = -f.m * (2.0 * f.alpha * (dw.cross(f.e) + f.omega.cross(de)) + f.beta * de);
  const Vec3 dF_turn = -f.rhoA * f.alpha * f.alpha * (de - de_prev);
  w.f[f.body].head<3>() -= f.xc.cross(dF_c) + f.origin.cross(dF_turn);
  w.f[f.body].tail<3>() -= dF_c + dF_turn;
}

// The loads' change along the tangent: a follower load turns with its body's twist W, δf = W ×* f; a fixed
// one keeps its force while its point moves by δx = W_v + W_ω × x: the moment δx × F.
void loads_tangent(const std::vector<BodyLoad>& loads, Tangent& w) {
  for (const BodyLoad& L : loads) {
    if (!w.inside[L.body]) continue;
    const Vec6& W = w.W[L.body];
    const AppliedLoad& l = L.load;
    if (L.follower) {
      Vec6 fl;
      fl << l.x.cross(l.F) + l.tau, l.F;
      w.f[L.body] -= crossf(W, fl);
    } else {
      const Vec3 dx = W.tail<3>() + W.head<3>().cross(l.x);
      w.f[L.body].head<3>() -= dx.cross(l.F);
    }
  }
}

}  // namespace

// (Outside the anonymous namespace: ResidualTranspose::Prepared, declared in a header, keeps one.)
namespace detail {

// The loads, element states and flowing rfes' terms at the state of d (after the RNEA): what the tangents of
// the loads' and elements' forces start from.
struct LoadTerms {
  std::vector<BodyLoad> loads;
  std::vector<ElementState> elements;
  std::vector<FlowTerm> flows;
  std::vector<ContactForce> contacts;
  std::vector<Eigen::Matrix<double, 6, 24>> contact_J;
  LoadTerms() = default;
  LoadTerms(const System& sys, const Data& d) { at(sys, d); }
  /// The terms at the state of d (the vectors keep their capacity).
  void at(const System& sys, const Data& d) {
    loads.clear(), elements.clear(), flows.clear(), contacts.clear(), contact_J.clear();
    for_each_body_load(sys, d, true, [&](int body, const AppliedLoad& a, bool follower) {
      loads.push_back({body, follower, a});
    });
    for (const ForceElement& E : sys.elements) elements.push_back(element_state(sys, d, E, true));
    for_each_flow_term(sys, d, true, [&](const FlowTerm& f) { flows.push_back(f); });
    if (!sys.contacts.empty())
      for_each_contact_force(sys, d, true, [&](const ContactForce& c) {
        contacts.push_back(c);
        contact_J.push_back(contact_jacobian(sys, c));
      });
    bodies.clear();
    for (const BodyLoad& L : loads) bodies.push_back(L.body);
    for (const ForceElement& E : sys.elements) bodies.push_back(E.body_a), bodies.push_back(E.body_b);
    for (const ContactForce& c : contacts) bodies.push_back(c.body_a), bodies.push_back(c.body_b);
    for (const FlowTerm& f : flows) bodies.push_back(f.body), bodies.push_back(f.prev);
    bodies.erase(std::remove(bodies.begin(), bodies.end(), -1), bodies.end());
    std::sort(bodies.begin(), bodies.end());
    bodies.erase(std::unique(bodies.begin(), bodies.end()), bodies.end());
  }
  /// Whether there are none.
  bool empty() const { return loads.empty() && elements.empty() && contacts.empty() && flows.empty(); }
  std::vector<int> bodies;  // the bodies whose tangents (W, δv, δf̄) the terms read or write, once each
  // The tangents of the loads, the elements' and the contacts' forces and the flowing material's loads.
  void tangent(const Data& d, const System& sys, Tangent& w) const {
    loads_tangent(loads, w);
    for (std::size_t k = 0; k < elements.size(); ++k) element_tangent(sys, d, sys.elements[k], elements[k], w);
    for (std::size_t k = 0; k < contacts.size(); ++k) contact_tangent(contacts[k], contact_J[k], w);
    for (const FlowTerm& f : flows) flow_tangent(f, w);
  }
};

}  // namespace detail

namespace {

using detail::LoadTerms;

// The matrices of x ↦ v ×m x and x ↦ x ×* f.
Mat6 motion_cross_matrix(const Vec6& v) {
  Mat6 X;
  for (int i = 0; i < 6; ++i) X.col(i) = crossm(v, Vec6::Unit(i));
  return X;
}
Mat6 force_cross_matrix(const Vec6& f) {
  Mat6 X;
  for (int i = 0; i < 6; ++i) X.col(i) = crossf(Vec6::Unit(i), f);
  return X;
}

// The inertial part of the tangent in closed form over subtrees (the idea of Carpentier & Mansard's RNEA
// derivatives, in the global spatial vectors of the book). Turning q_j by δq_j = 1 turns the subtree after its use
// u_j about the axis s = s_j: with v⁻, a⁻ the velocity and acceleration before u_j, w = s ×m v⁻ and z = s ×m a⁻,
// every body p it carries has
//   W_p = s,  δv_p = s ×m (v_p − v⁻),  δa_p = s ×m (a_p − a⁻) − w ×m (v_p − v⁻)
// (the later axes s_u and their rates ṡ_u = v_before ×m s_u turned, by Jacobi's identity), and δq̇_j = 1 gives
//   W_p = 0,  δv_p = s,  δa_p = s ×m v_p − 2 w.
// Put into δf_p = I δa + δv ×* I v + v ×* I δv + δI a + v ×* δI v (Tangent::body_force) and summed over the subtree
// of X, with P_p = I_p (v_p ×m), R_p = −(h_p ×*)(v_p ×m) (x ↦ x ×* h_p), h_p = I_p v_p, g_p = I_p a_p,
//   position: δf̄_X = Ī (w ×m v⁻ − z) + Ḡ w + H̄ s − w ×* h̄ + s ×* ḡ,
//   rate:     δf̄_X = −Ḡ s − 2 Ī w + s ×* h̄,
// where Ī, ḡ, h̄ sum I_p, g_p, h_p and Ḡ, H̄ the symmetric P_p + P_pᵀ and the skew R_p − R_pᵀ over the subtree
// (v ×* = −(v ×m)ᵀ, and x ↦ x ×* h is skew). A row k (use u_k on body b_k, r_k = s_kᵀ f̄_{b_k}) sees X = b_j if b_k
// is b_j or above it, X = b_k if below (nothing on another branch), and δs_k = s ×m s_k if u_k is after u_j. Below,
// by (x ×* f)ᵀ m =
// −fᵀ (x ×m m), a pair costs three dot products with the row's β_k = Ī s_k, γ_k = Ḡ s_k + s_k ×* h̄ and
// δ_k = H̄ᵀ s_k − s_k ×* ḡ + s_k ×* f̄ (X = b_k):
//   position: δr_k = β_k·(w ×m v⁻ − z) + γ_k·w + δ_k·s,   rate: δr_k = −γ_k·s − 2 β_k·w.
struct InertialTangent {
  std::vector<Mat6> I, G, H;  // (nbodies) Ī, Ḡ, H̄
  std::vector<Vec6> h, g;     // (nbodies) h̄, ḡ
  std::vector<Vec6> vb, ab;   // (nuses) the velocity and acceleration before each use
  std::vector<Vec6> beta, gamma, delta;  // (nq) each row's β, γ, δ

  // At the state of d after the RNEA pass.
  InertialTangent(const System& sys, const Data& d)
      : I(sys.nbodies), G(sys.nbodies), H(sys.nbodies), h(sys.nbodies), g(sys.nbodies), vb(sys.nuses), ab(sys.nuses),
        beta(sys.nq), gamma(sys.nq), delta(sys.nq) {
    const Vec6 O6 = Vec6::Zero(), a0 = gravity_acceleration(sys, d);
    for (int p = 0; p < sys.nbodies; ++p) {
      const Mat6 V = motion_cross_matrix(d.v[p]);
      h[p] = d.I[p] * d.v[p], g[p] = d.I[p] * d.a[p];
      const Mat6 P = d.I[p] * V, R = -force_cross_matrix(h[p]) * V;
      I[p] = d.I[p], G[p] = P + P.transpose(), H[p] = R - R.transpose();
      // a_u⁻ and v_u⁻ along the body's uses: a += (v ×m s_u) q̇_u + s_u q̈_u, v += s_u q̇_u
      Vec6 v = parent_value(sys, d.v, p, O6), a = parent_value(sys, d.a, p, a0);
      for (int u = sys.use_start[p]; u < sys.use_start[p + 1]; ++u) {
        const int i = sys.use_coord[u];
        vb[u] = v, ab[u] = a;
        a += crossm(v, d.axes[u]) * d.qda(i) + d.axes[u] * d.qdda(i);
        v += d.axes[u] * d.qda(i);
      }
    }
    accumulate_subtrees(sys, I), accumulate_subtrees(sys, G), accumulate_subtrees(sys, H);
    accumulate_subtrees(sys, h), accumulate_subtrees(sys, g);
    for (int k = 0; k < sys.nq; ++k) {
      const int b = sys.coords[sys.free_coords[k]].body;
      const Vec6& s = d.axes[sys.q_use[k]];
      beta[k] = I[b] * s;
      gamma[k] = G[b] * s + crossf(s, h[b]);
      delta[k] = H[b].transpose() * s - crossf(s, g[b]) + crossf(s, d.sf[b]);
    }
  }

  // Columns ∂r/∂q_j and ∂r/∂q̇_j (inertial part) of the free coordinate j (use uj on body bj) into dq, dqd; inside
  // (nbodies) flags bj's subtree, above the bodies from bj to the root.
  void columns(const System& sys, const Data& d, int uj, int bj, const std::vector<char>& inside,
               const std::vector<char>& above, Eigen::Ref<VecX> dq, Eigen::Ref<VecX> dqd) const {
    const Vec6& s = d.axes[uj];
    const Vec6 w = crossm(s, vb[uj]), x = crossm(w, vb[uj]) - crossm(s, ab[uj]);  // x = w ×m v⁻ − z
    const Vec6 F = I[bj] * x + G[bj] * w + H[bj] * s - crossf(w, h[bj]) + crossf(s, g[bj]);
    const Vec6 Fd = -(G[bj] * s) - 2.0 * (I[bj] * w) + crossf(s, h[bj]);
    for (int k = 0; k < sys.nq; ++k) {
      const int b = sys.coords[sys.free_coords[k]].body, u = sys.q_use[k];
      if (inside[b] && (b != bj || u > uj)) {  // below u_j: X = b_k, s_k turned
        dq(k) = beta[k].dot(x) + gamma[k].dot(w) + delta[k].dot(s);
        dqd(k) = -gamma[k].dot(s) - 2.0 * beta[k].dot(w);
      } else if (above[b]) {  // X = b_j
        dq(k) = d.axes[u].dot(F);
        dqd(k) = d.axes[u].dot(Fd);
      } else {
        dq(k) = dqd(k) = 0.0;
      }
    }
  }
};

// The loads', elements', contacts' and flows' part of the columns of q_j and q̇_j (use uj, inside flagging the
// subtree it carries), added into dq and dqd: their tangents at the bodies they touch (terms.bodies), carried as
// above (W_p and δv_p), each body's δf handed to the rows of the bodies from it to the root (a body's free
// coordinates: q_index[p] ... q_index[p] + nq_of[p] − 1), δr_k = s_kᵀ δf̄_{b_k} − δQ_k.
void terms_columns(const System& sys, const Data& d, const LoadTerms& terms, const InertialTangent& it, int uj,
                   const std::vector<char>& inside, Tangent& w, Eigen::Ref<VecX> dq, Eigen::Ref<VecX> dqd) {
  const Vec6& s = d.axes[uj];
  const int j = sys.use_q[uj];  // δq_j = 1 or δq̇_j = 1 (a drum pays out with it)
  for (const bool position : {true, false}) {
    w.dq.setZero(), w.dqd.setZero(), w.dQ.setZero();
    (position ? w.dq : w.dqd)(j) = 1.0;
    for (const int p : terms.bodies) {
      w.inside[p] = inside[p];
      w.f[p].setZero();
      w.W[p] = position && inside[p] ? s : Vec6::Zero();
      w.v[p] = !inside[p] ? Vec6::Zero() : position ? Vec6(crossm(s, d.v[p] - it.vb[uj])) : s;
    }
    terms.tangent(d, sys, w);
    auto col = position ? dq : dqd;
    for (const int b : terms.bodies)
      if (!w.f[b].isZero(0.0))
        for (int p = b; p >= 0; p = sys.parent[p])
          for (int k = sys.q_index[p]; k < sys.q_index[p] + sys.nq_of[p]; ++k)
            col(k) += d.axes[sys.q_use[k]].dot(w.f[b]);
    col -= w.dQ;
  }
}

}  // namespace

VecX rnea_directional_derivative(const System& sys, Data& d, const VecX& dq, const VecX& dqd, const VecX& dqdd) {
  spatial_kinematics(sys, d);
  rnea_pass(sys, d);
  const LoadTerms terms(sys, d);
  Tangent w(sys);
  w.dq = dq, w.dqd = dqd;
  std::vector<Vec6> W_before(sys.nuses);  // the twist carrying each use's axis: δs_u = W ×m s_u
  static const Vec6 O6 = Vec6::Zero();
  for (int p = 0; p < sys.nbodies; ++p) {
    Vec6 W = parent_value(sys, w.W, p, O6), v = parent_value(sys, d.v, p, O6);
    Vec6 dv = parent_value(sys, w.v, p, O6), da = parent_value(sys, w.a, p, O6);
    for (int u = sys.use_start[p]; u < sys.use_start[p + 1]; ++u) {
      const int i = sys.use_coord[u], k = sys.use_q[u];
      const Vec6& s = d.axes[u];
      const double qd = d.qda(i), dqu = k >= 0 ? dq(k) : 0.0, dqdu = k >= 0 ? dqd(k) : 0.0;
      const double dqddu = k >= 0 ? dqdd(k) : 0.0;
      W_before[u] = W;
      const Vec6 ds = crossm(W, s);
      // c += (v ×m s) q̇ and a += s q̈, v += s q̇ (v: the velocity before this use), differentiated
      da += (crossm(dv, s) + crossm(v, ds)) * qd + ds * d.qdda(i) + crossm(v, s) * dqdu + s * dqddu;
      dv += ds * qd + s * dqdu;
      v += s * qd;
      W += s * dqu;
    }
    w.inside[p] = true;
    w.W[p] = W, w.v[p] = dv, w.a[p] = da;
    w.f[p] = Tangent::body_force(d, p, W, dv, da);
  }
  terms.tangent(d, sys, w);
  accumulate_subtrees(sys, w.f);
  VecX out(sys.nq);
  for (int k = 0; k < sys.nq; ++k) {
    const int i = sys.free_coords[k], b = sys.coords[i].body, u = sys.q_use[k];
    out(k) = d.axes[u].dot(w.f[b]) + crossm(W_before[u], d.axes[u]).dot(d.sf[b]) - w.dQ(k);
    // −δQ of the coordinate's own spring-damping law and its further laws
    const Coordinate& c = sys.coords[i];
    out(k) += c.spring.variation(dq(k), dqd(k), d.spring_scale(i));
    if (!c.laws.empty()) {
      const auto [dQ_dq, dQ_dqd] = coordinate_derivatives(sys, d, i);
      out(k) -= dQ_dq * dq(k) + dQ_dqd * dqd(k);
    }
  }
  return out;
}

// What the reverse mode reads of a state, whatever μ: the loads' and elements' states and their laws'
// derivatives, each free coordinate's own stiffness and damping and its axis's moment s_u ×* f̄_b, each use's
// velocity before it and v ×m s_u, each body's I v and I a.
struct ResidualTranspose::Prepared {
  struct Law {
    ExtensionDerivatives F, P;  // the element's law and, for a wound rope, its pull
    Vec3 g_half;                // ½ λ μ g of a heavy rope
  };
  LoadTerms terms;
  std::vector<Law> laws;            // per element
  VecX k_own, c_own;                // (nq) ∂Q/∂q, ∂Q/∂q̇ of each free coordinate's own laws
  std::vector<Vec6> s_f;            // (nq) s_u ×* f̄_b of the coordinate's use
  std::vector<Vec6> v_before, v_s;  // (nuses) the velocity before each use, and v ×m s_u
  std::vector<Vec6> Iv, Ia;         // (nbodies)
  std::vector<Vec6> G, Wu, H, Wb, vb, ab;  // the sweeps' adjoints (buffers)
};

ResidualTranspose::ResidualTranspose(const System& sys) : sys_(sys), p_(std::make_unique<Prepared>()) {
  Prepared& p = *p_;
  const int nb = sys.nbodies;
  p.laws.resize(sys.elements.size());
  p.k_own.resize(sys.nq), p.c_own.resize(sys.nq), p.s_f.resize(sys.nq);
  p.v_before.resize(sys.nuses), p.v_s.resize(sys.nuses), p.Wu.resize(sys.nuses);
  for (auto* x : {&p.Iv, &p.Ia, &p.G, &p.H, &p.Wb, &p.vb, &p.ab}) x->resize(nb);
  out_ = {VecX(sys.nq), VecX(sys.nq), VecX(sys.nq), VecX(sys.np), VecX(sys.np), VecX(sys.np)};
}

ResidualTranspose::~ResidualTranspose() = default;

void ResidualTranspose::prepare(Data& d) {
  const System& sys = sys_;
  Prepared& p = *p_;
  spatial_kinematics(sys, d);
  rnea_pass(sys, d);
  p.terms.at(sys, d);
  for (std::size_t k = 0; k < sys.elements.size(); ++k) {
    const ForceElement& E = sys.elements[k];
    const ElementState& st = p.terms.elements[k];
    p.laws[k].F = E.law->derivatives(d.t, st.extension(), d.load_factor);
    if (!E.windings.empty()) p.laws[k].P = E.law->pull_derivatives(d.t, st.extension());
    p.laws[k].g_half = 0.5 * d.load_factor * E.law->span_mass_rate() * sys.gravity;
  }
  for (int k = 0; k < sys.nq; ++k) {
    const int i = sys.free_coords[k], b = sys.coords[i].body, u = sys.q_use[k];
    const Coordinate& c = sys.coords[i];
    std::tie(p.k_own(k), p.c_own(k)) = c.spring.derivatives(d.spring_scale(i));
    if (!c.laws.empty()) {
      const auto [dQ_dq, dQ_dqd] = coordinate_derivatives(sys, d, i);
      p.k_own(k) += dQ_dq, p.c_own(k) += dQ_dqd;
    }
    p.s_f[k] = crossf(d.axes[u], d.sf[b]);  // (W ×m s)·f = W·(s ×* f)
  }
  for (int b = 0; b < sys.nbodies; ++b) {
    Vec6 v = sys.parent[b] >= 0 ? d.v[sys.parent[b]] : Vec6::Zero();
    for (int u = sys.use_start[b]; u < sys.use_start[b + 1]; ++u) {
      p.v_before[u] = v, p.v_s[u] = crossm(v, d.axes[u]);
      v += d.axes[u] * d.qda(sys.use_coord[u]);
    }
    p.Iv[b] = d.I[b] * d.v[b], p.Ia[b] = d.I[b] * d.a[b];
  }
}

const ResidualVjp& ResidualTranspose::apply(const Data& d, const VecX& mu) {
  const System& sys = sys_;
  Prepared& p = *p_;
  ResidualVjp& out = out_;
  for (VecX* x : {&out.q, &out.qd, &out.qdd, &out.pq, &out.pqd, &out.pqdd}) x->setZero();
  const int nb = sys.nbodies;
  // δr_k = s_uᵀ δf̄_b + (W_before ×m s_u)ᵀ f̄_b + passive: the adjoint G of each subtree sum and of each W_before
  std::fill(p.G.begin(), p.G.end(), Vec6::Zero());
  std::fill(p.Wu.begin(), p.Wu.end(), Vec6::Zero());
  for (int k = 0; k < sys.nq; ++k) {
    const int b = sys.coords[sys.free_coords[k]].body, u = sys.q_use[k];
    p.G[b] += d.axes[u] * mu(k);
    p.Wu[u] += mu(k) * p.s_f[k];
    out.q(k) -= p.k_own(k) * mu(k);
    out.qd(k) -= p.c_own(k) * mu(k);
  }
  // subtree sums transposed: each body's δf meets the adjoints of its own and its ancestors' sums
  std::vector<Vec6>&H = p.H, &Wb = p.Wb, &vb = p.vb, &ab = p.ab;
  for (int b = 0; b < nb; ++b) H[b] = p.G[b] + (sys.parent[b] >= 0 ? H[sys.parent[b]] : Vec6::Zero());
  // adjoints of each body's W, δv and δa at the end of its joint
  std::fill(Wb.begin(), Wb.end(), Vec6::Zero());
  std::fill(vb.begin(), vb.end(), Vec6::Zero());
  std::fill(ab.begin(), ab.end(), Vec6::Zero());
  auto point_adjoint = [&](int b, const Vec3& x, const Vec3& dx_bar, const Vec3& dvel_bar) {
    if (b < 0) return;
    // dvel = δv_O + δω × x + ω × dx, dx = W_v + W_ω × x
    vb[b].tail<3>() += dvel_bar;
    vb[b].head<3>() += x.cross(dvel_bar);
    const Vec3 dx = dx_bar + dvel_bar.cross(d.v[b].head<3>());
    Wb[b].tail<3>() += dx;
    Wb[b].head<3>() += x.cross(dx);
  };
  const LoadTerms& terms = p.terms;
  for (std::size_t k = 0; k < terms.elements.size(); ++k) {
    const ForceElement& E = sys.elements[k];
    const ElementState& st = terms.elements[k];
    const Prepared::Law& law = p.laws[k];
    const ExtensionDerivatives& F = law.F;
    // δf_b −= (x_b × df, df), δf_a += (x_a × df, df)
    Vec3 df = Vec3::Zero();
    if (E.body_b >= 0) df += st.xb.cross(H[E.body_b].head<3>()) - H[E.body_b].tail<3>();
    if (E.body_a >= 0) df -= st.xa.cross(H[E.body_a].head<3>()) - H[E.body_a].tail<3>();
    // df = (F_l δl + F_l̇ δl̇ + F_s δs + F_ṡ δṡ) e + F δe; δl̇ = δe·(v_b − v_a) + e·δḋ; δl = e·δd;
    // δe = (1 − e eᵀ) δd / l; each free winding's row −r_k (c_k δP + P c_k' δq̇_k) adds −μ_k r_k c_k (P_l, P_l̇, P_s,
    // P_ṡ) to (δl̄, δl̇̄, δs̄, δṡ̄), and δs = Σ r_k δq_k
    const double ed = st.e.dot(df);
    // a heavy rope's weights δw_B = −δw_A = ½ λ μ δs g, and its pull's ½ λ μ g·δd
    double dl_bar = F.l * ed, dld_bar = F.ld * ed, s_bar = F.s * ed + law.g_half.dot(df), sd_bar = F.sd * ed;
    double pull_bar = 0.0;  // Σ μ_k r_k c_k
    if (!E.windings.empty()) {
      const ExtensionDerivatives& P = law.P;
      for (const Winding& wi : E.windings)
        if (const int k = sys.coords[wi.coord].free_index; k >= 0) {
          const auto [c, dc] = wi.factor(d.qda(wi.coord));
          const double m = mu(k) * wi.radius;
          dl_bar -= m * c * P.l, dld_bar -= m * c * P.ld, s_bar -= m * c * P.s, sd_bar -= m * c * P.sd;
          pull_bar += m * c;
          out.qd(k) -= m * st.P * dc;
        }
      for (const Winding& wi : E.windings)
        if (const int k = sys.coords[wi.coord].free_index; k >= 0)
          out.q(k) += wi.radius * s_bar, out.qd(k) += wi.radius * sd_bar;
    }
    const Vec3 de_bar = st.F * df + (st.vb - st.va) * dld_bar;
    const Vec3 ddd_bar = st.e * dld_bar;
    const Vec3 dd_bar = st.e * dl_bar + (de_bar - st.e * st.e.dot(de_bar)) / st.l - pull_bar * law.g_half;
    point_adjoint(E.body_b, st.xb, dd_bar, ddd_bar);
    point_adjoint(E.body_a, st.xa, -dd_bar, -ddd_bar);
  }
  for (std::size_t k = 0; k < terms.contacts.size(); ++k) {
    // contact_tangent transposed: ε̄ = Jᵀ (h_a − h_b), and the moved points' moments, x_c × f on b and a
    const ContactForce& c = terms.contacts[k];
    const Vec6 ha = c.body_a >= 0 ? H[c.body_a] : Vec6::Zero(), hb = c.body_b >= 0 ? H[c.body_b] : Vec6::Zero();
    Eigen::Matrix<double, 24, 1> eps_bar = terms.contact_J[k].transpose() * (ha - hb);
    const Vec3 gb = c.f.cross(hb.head<3>()), ga = c.f.cross(ha.head<3>());
    eps_bar.segment<3>(15) += gb, eps_bar.segment<3>(12) += c.x.cross(gb);
    eps_bar.segment<3>(3) -= ga, eps_bar.segment<3>(0) -= c.x.cross(ga);
    if (c.body_a >= 0) Wb[c.body_a] += eps_bar.segment<6>(0), vb[c.body_a] += eps_bar.segment<6>(6);
    if (c.body_b >= 0) Wb[c.body_b] += eps_bar.segment<6>(12), vb[c.body_b] += eps_bar.segment<6>(18);
  }
  for (const FlowTerm& f : terms.flows) {
    // flow_tangent transposed: with F̄ = x × h_ω − h_v the adjoints of δF_C (x = x_C) and δF_turn (x = origin),
    //   ē = −m (2α F̄_C × ω + β F̄_C) − ρA α² F̄_turn,  ē_prev = ρA α² F̄_turn,  δω̄ = −2mα e × F̄_C,
    // and δe = W_ω × e: W̄_ω += e × ē (likewise for the previous rfe's axis)
    const Vec6& h = H[f.body];
    const Vec3 Fc = f.xc.cross(h.head<3>()) - h.tail<3>(), Ft = f.origin.cross(h.head<3>()) - h.tail<3>();
    const Vec3 e_bar = -f.m * (2.0 * f.alpha * Fc.cross(f.omega) + f.beta * Fc) - f.rhoA * f.alpha * f.alpha * Ft;
    vb[f.body].head<3>() -= 2.0 * f.m * f.alpha * f.e.cross(Fc);
    Wb[f.body].head<3>() += f.e.cross(e_bar);
    if (f.prev >= 0) Wb[f.prev].head<3>() += f.e_prev.cross(f.rhoA * f.alpha * f.alpha * Ft);
  }
  for (const BodyLoad& L : terms.loads) {
    const AppliedLoad& l = L.load;
    const Vec6& h = H[L.body];
    if (L.follower) {  // δf −= W ×* f: W̄ += h ×* f
      Vec6 fl;
      fl << l.x.cross(l.F) + l.tau, l.F;
      Wb[L.body] += crossf(h, fl);
    } else {  // δf_ω −= δx × F, δx = W_v + W_ω × x
      const Vec3 dx = h.head<3>().cross(l.F);
      Wb[L.body].tail<3>() += dx;
      Wb[L.body].head<3>() += l.x.cross(dx);
    }
  }
  // δf_p = I δa + δv ×* I v + v ×* I δv + δI a + v ×* δI v, δI x = W ×* I x − I (W ×m x), transposed
  for (int b = 0; b < nb; ++b) {
    const Mat6& I = d.I[b];
    const Vec6& h = H[b];
    const Vec6& v = d.v[b];
    const Vec6 z = crossm(v, h), Ih = I * h, Iz = I * z;
    ab[b] += Ih;
    vb[b] += -crossf(h, p.Iv[b]) - Iz;
    Wb[b] += -crossf(h, p.Ia[b]) - crossf(d.a[b], Ih) + crossf(z, p.Iv[b]) + crossf(v, Iz);
  }
  // the forward sweep transposed, leaves to root, each body's uses last to first
  for (int b = nb - 1; b >= 0; --b) {
    Vec6 W = Wb[b], dv = vb[b], da = ab[b];
    for (int u = sys.use_start[b + 1] - 1; u >= sys.use_start[b]; --u) {
      const int i = sys.use_coord[u], k = sys.use_q[u], j = sys.use_drive[u];
      const Vec6& s = d.axes[u];
      const Vec6& v = p.v_before[u];
      const double qd = d.qda(i), qdd = d.qdda(i);
      // W += s δq, δv += δs q̇ + s δq̇, δa += (δv ×m s + v ×m δs) q̇ + δs q̈ + (v ×m s) δq̇ + s δq̈: the adjoints
      // of a free coordinate's (δq, δq̇, δq̈), or of a prescribed one's motion
      const double wq = s.dot(W), wqd = s.dot(dv) + p.v_s[u].dot(da), wqdd = s.dot(da);
      if (k >= 0) out.q(k) += wq, out.qd(k) += wqd, out.qdd(k) += wqdd;
      if (j >= 0) out.pq(j) += wq, out.pqd(j) += wqd, out.pqdd(j) += wqdd;
      Vec6 ds = qd * dv;
      dv += qd * crossf(s, da);
      ds += -qd * crossf(v, da) + qdd * da;
      W += crossf(s, ds) + p.Wu[u];  // δs = W ×m s
    }
    if (sys.parent[b] >= 0) Wb[sys.parent[b]] += W, vb[sys.parent[b]] += dv, ab[sys.parent[b]] += da;
  }
  return out;
}

ResidualVjp rnea_vector_jacobian_product(const System& sys, Data& d, const VecX& mu) {
  ResidualTranspose transpose(sys);
  transpose.prepare(d);
  return transpose.apply(d, mu);
}

std::pair<MatX, MatX> rnea_derivatives(const System& sys, Data& d) {
  spatial_kinematics(sys, d);
  rnea_pass(sys, d);
  // The loads (their geometric term) and the states of the elements and flowing rfes whose forces
  // change with the state.
  const LoadTerms terms(sys, d);
  const InertialTangent inertial(sys, d);
  MatX dq(sys.nq, sys.nq), dqd(sys.nq, sys.nq);
  Tangent w(sys);
  std::vector<char> inside(sys.nbodies), above(sys.nbodies);
  for (int j = 0; j < sys.nq; ++j) {
    const int i = sys.free_coords[j], b = sys.coords[i].body, u = sys.q_use[j];
    interruption_point();
    std::fill(above.begin(), above.end(), 0);
    for (int p = b; p >= 0; p = sys.parent[p]) above[p] = 1;
    for (int p = 0; p < sys.nbodies; ++p) inside[p] = p == b || (p > b && sys.parent[p] >= 0 && inside[sys.parent[p]]);
    inertial.columns(sys, d, u, b, inside, above, dq.col(j), dqd.col(j));
    if (!terms.empty()) terms_columns(sys, d, terms, inertial, u, inside, w, dq.col(j), dqd.col(j));
    // −∂Q_j/∂(q_j, q̇_j) of the coordinate's own spring-damping law and its further laws.
    const Coordinate& c = sys.coords[i];
    const auto [k_own, c_own] = c.spring.derivatives(d.spring_scale(i));
    dq(j, j) -= k_own;
    dqd(j, j) -= c_own;
    if (!c.laws.empty()) {
      const auto [dQ_dq, dQ_dqd] = coordinate_derivatives(sys, d, i);
      dq(j, j) -= dQ_dq;
      dqd(j, j) -= dQ_dqd;
    }
  }
  return {dq, dqd};
}

}  // namespace rigidfem

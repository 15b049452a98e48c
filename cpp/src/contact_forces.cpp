#include "rigidfem/contact_forces.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <utility>
#include <vector>

#include <unsupported/Eigen/AutoDiff>

#include "rigidfem/errors.hpp"

namespace rigidfem {

namespace {

template <class S>
using V3 = Eigen::Matrix<S, 3, 1>;
using Eps = Eigen::Matrix<double, 24, 1>;
using AD = Eigen::AutoDiffScalar<Eps>;

// The spatial velocity (ω, v_O) of body b (zero for the ground): d.v, or from Ṫ = [Ṙ ṗ]: ω̃ = Ṙ Rᵀ, v_O = ṗ − ω × p.
Vec6 body_velocity(const Data& d, int b, bool spatial) {
  if (b < 0) return Vec6::Zero();
  if (spatial) return d.v[b];
  const Mat3 W = d.Td[b].topLeftCorner<3, 3>() * d.T[b].topLeftCorner<3, 3>().transpose();
  const Vec3 w(0.5 * (W(2, 1) - W(1, 2)), 0.5 * (W(0, 2) - W(2, 0)), 0.5 * (W(1, 0) - W(0, 1)));
  Vec6 V;
  V << w, d.Td[b].block<3, 1>(0, 3) - w.cross(d.T[b].block<3, 1>(0, 3));
  return V;
}

Vec3 global(const Data& d, int b, const Vec3& x) { return b < 0 ? x : Vec3((d.T[b] * x.homogeneous()).head<3>()); }
Vec3 turned(const Data& d, int b, const Vec3& n) { return b < 0 ? n : Vec3(d.T[b].topLeftCorner<3, 3>() * n); }

template <class S>
S clamp01(const S& x) {
  return x < 0.0 ? S(0.0) : (x > 1.0 ? S(1.0) : x);
}

// The parameters (s, t) of the closest points a0 + s (a1 − a0), b0 + t (b1 − b0) of two segments (a point where
// a segment has no length; Ericson, Real-Time Collision Detection 5.1.9): the unconstrained minimum, clamped.
template <class S>
void closest_points(const V3<S>& a0, const V3<S>& a1, const V3<S>& b0, const V3<S>& b1, S& s, S& t) {
  const V3<S> d1 = a1 - a0, d2 = b1 - b0, r = a0 - b0;
  const S a = d1.dot(d1), e = d2.dot(d2), f = d2.dot(r);
  const double tiny = 1e-24;
  if (a <= tiny && e <= tiny) {
    s = t = S(0.0);
  } else if (a <= tiny) {
    s = S(0.0);
    t = clamp01(S(f / e));
  } else {
    const S c = d1.dot(r);
    if (e <= tiny) {
      t = S(0.0);
      s = clamp01(S(-c / a));
    } else {
      const S b = d1.dot(d2), denom = a * e - b * b;
      s = denom > tiny * a * e ? clamp01(S((b * f - c * e) / denom)) : S(0.0);
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = S(0.0);
        s = clamp01(S(-c / a));
      } else if (t > 1.0) {
        t = S(1.0);
        s = clamp01(S((b - c) / a));
      }
    }
  }
}

template <class S>
struct Evaluated {
  V3<S> x, n, f, vt;
  S gap, gap_rate, Fn;
};

// One overlap's gap and force at the state moved by ε = (W_a, δV_a, W_b, δV_b): a material point x of body k is
// then at x + W_ω × x + W_v, the velocity field of body k at a place y is (v_O + δv_O) + (ω + δω) × y (first order:
// what the derivative at ε = 0 needs). S = double with ε = 0 evaluates; S = AD differentiates.
template <class S>
Evaluated<S> evaluate(const ContactForce& c, const ContactLaw& law, const Eigen::Matrix<S, 24, 1>& eps) {
  const auto moved = [&](int k, const Vec3& x) -> V3<S> {
    const V3<S> X = x.template cast<S>();
    const V3<S> w = eps.template segment<3>(12 * k), v = eps.template segment<3>(12 * k + 3);
    return X + w.cross(X) + v;
  };
  const auto velocity = [&](int k, const V3<S>& y) -> V3<S> {
    const Vec6& V = k == 0 ? c.Va : c.Vb;
    const V3<S> w = V.head<3>().template cast<S>() + eps.template segment<3>(12 * k + 6);
    return V.tail<3>().template cast<S>() + eps.template segment<3>(12 * k + 9) + w.cross(y);
  };
  Evaluated<S> out;
  if (c.plane) {  // o, n of body a; x_B of body b
    const V3<S> o = moved(0, c.p[0]), xb = moved(1, c.p[2]);
    const V3<S> n0 = c.p[1].template cast<S>();
    out.n = n0 + eps.template segment<3>(0).cross(n0);  // turned with a (first order)
    out.gap = out.n.dot(xb - o) - c.rb;
    out.x = xb - (c.rb + 0.5 * out.gap) * out.n;
  } else {
    const V3<S> a0 = moved(0, c.p[0]), a1 = moved(0, c.p[1]), b0 = moved(1, c.p[2]), b1 = moved(1, c.p[3]);
    S s, t;
    closest_points(a0, a1, b0, b1, s, t);
    const V3<S> pa = a0 + s * (a1 - a0), dist = b0 + t * (b1 - b0) - pa;
    using std::sqrt;
    const S l = sqrt(dist.dot(dist));
    out.n = dist / l;
    out.gap = l - c.ra - c.rb;
    out.x = pa + (c.ra + 0.5 * out.gap) * out.n;
  }
  const V3<S> vrel = velocity(1, out.x) - velocity(0, out.x);
  out.gap_rate = out.n.dot(vrel);
  out.vt = vrel - out.gap_rate * out.n;
  out.Fn = law.normal(S(-out.gap), S(-out.gap_rate));
  out.f = out.Fn * out.n + law.friction(out.Fn, out.vt);
  return out;
}

// The features of shape `s` against the plane (o, n): its points and their radius.
template <class Visit>
void shape_points(const Shape& s, const Data& d, Visit&& visit) {
  switch (s.kind) {
    case ShapeKind::Sphere:
      visit(global(d, s.body, s.a), s.radius);
      break;
    case ShapeKind::Capsule:
      visit(global(d, s.body, s.a), s.radius);
      visit(global(d, s.body, s.b), s.radius);
      break;
    case ShapeKind::Box:
      for (int k = 0; k < 8; ++k) {
        const Vec3 corner((k & 1 ? 1.0 : -1.0) * s.h(0), (k & 2 ? 1.0 : -1.0) * s.h(1), (k & 4 ? 1.0 : -1.0) * s.h(2));
        visit(global(d, s.body, s.a + s.R * corner), 0.0);
      }
      break;
    case ShapeKind::HalfSpace:
      break;
  }
}

// Finishes c (its geometry set) at ε = 0; true if the shapes overlap.
bool overlap(ContactForce& c, const ContactLaw& law, double t) {
  const Evaluated<double> e = evaluate<double>(c, law, Eps::Zero());
  if (!(e.gap < 0.0)) return false;
  if (!std::isfinite(e.gap) || !e.n.allFinite())
    throw SimulationError(t, "the closest points of two shapes of a contact coincide (its normal is undefined)");
  c.x = e.x, c.n = e.n, c.f = e.f, c.vt = e.vt, c.gap = e.gap, c.gap_rate = e.gap_rate, c.Fn = e.Fn;
  return true;
}

}  // namespace

namespace {

// A half-space P against a shape O of another body: the point–plane features of O that overlap it.
void plane_pair(const System& sys, const Data& d, bool spatial, int k, const Shape& P, const Shape& O,
                const std::function<void(const ContactForce&)>& visit) {
  if (P.body == O.body) return;
  ContactForce c;
  c.contact = k, c.body_a = P.body, c.body_b = O.body, c.plane = true;
  c.Va = body_velocity(d, P.body, spatial), c.Vb = body_velocity(d, O.body, spatial);
  c.p[0] = global(d, P.body, P.a), c.p[1] = turned(d, P.body, P.n);
  shape_points(O, d, [&](const Vec3& x, double r) {
    c.p[2] = x, c.rb = r;
    if (c.p[1].dot(x - c.p[0]) - r < 0.0 && overlap(c, *sys.contacts[k].law, d.t)) visit(c);
  });
}

// A swept sphere (a sphere or a capsule) at the state: its segment (global) and radius.
struct Swept {
  int shape;
  Vec3 p0, p1;
  double radius, lo, hi;  // its extent along the sweep's axis
};

Swept swept(const System& sys, const Data& d, int k, int axis) {
  const Shape& S = sys.shapes[k];
  Swept w{k, global(d, S.body, S.a), global(d, S.body, S.kind == ShapeKind::Capsule ? S.b : S.a), S.radius, 0.0, 0.0};
  w.lo = std::min(w.p0(axis), w.p1(axis)) - w.radius, w.hi = std::max(w.p0(axis), w.p1(axis)) + w.radius;
  return w;
}

// Two swept spheres of bodies a and b: their bounding spheres, then the closest points of their segments.
void swept_pair(const System& sys, const Data& d, bool spatial, int k, const Swept& A, const Swept& B,
                const std::function<void(const ContactForce&)>& visit) {
  const int ba = sys.shapes[A.shape].body, bb = sys.shapes[B.shape].body;
  if (ba == bb) return;
  const double reach = 0.5 * ((A.p1 - A.p0).norm() + (B.p1 - B.p0).norm()) + A.radius + B.radius;
  if (!((0.5 * (A.p0 + A.p1 - B.p0 - B.p1)).norm() < reach)) return;
  ContactForce c;
  c.contact = k, c.body_a = ba, c.body_b = bb;
  c.Va = body_velocity(d, ba, spatial), c.Vb = body_velocity(d, bb, spatial);
  c.p[0] = A.p0, c.p[1] = A.p1, c.p[2] = B.p0, c.p[3] = B.p1, c.ra = A.radius, c.rb = B.radius;
  if (overlap(c, *sys.contacts[k].law, d.t)) visit(c);
}

// The pairs of two groups of swept spheres whose extents along x meet (sweep and prune: the extents sorted by
// their lower ends, each meeting the other group's open ones): O((n_a + n_b) log(n_a + n_b) + pairs) where the
// groups lie along x, against n_a n_b tests. Scratch per thread, kept between calls: no allocation once warm.
void swept_groups(const System& sys, const Data& d, bool spatial, int k, const std::vector<int>& a,
                  const std::vector<int>& b, const std::function<void(const ContactForce&)>& visit) {
  thread_local std::vector<std::pair<Swept, bool>> all;  // (shape, in group a)
  thread_local std::vector<const Swept*> open_a, open_b;
  all.clear(), open_a.clear(), open_b.clear();
  for (const int s : a) all.push_back({swept(sys, d, s, 0), true});
  for (const int s : b) all.push_back({swept(sys, d, s, 0), false});
  std::sort(all.begin(), all.end(), [](const auto& x, const auto& y) { return x.first.lo < y.first.lo; });
  for (const auto& [w, in_a] : all) {
    // the other group's open extents: those ending before this one starts are closed for good (the lower ends come
    // in order), the others meet it; its own group's are pruned when the other group's next one comes
    std::vector<const Swept*>& other = in_a ? open_b : open_a;
    other.erase(std::remove_if(other.begin(), other.end(), [&](const Swept* o) { return o->hi < w.lo; }), other.end());
    for (const Swept* o : other) in_a ? swept_pair(sys, d, spatial, k, w, *o, visit)
                                      : swept_pair(sys, d, spatial, k, *o, w, visit);
    (in_a ? open_a : open_b).push_back(&w);
  }
}

}  // namespace

void for_each_contact_force(const System& sys, const Data& d, bool spatial,
                            const std::function<void(const ContactForce&)>& visit) {
  thread_local std::vector<int> sa, sb;
  for (int k = 0; k < static_cast<int>(sys.contacts.size()); ++k) {
    const Contact& C = sys.contacts[k];
    const auto plane = [&](int s) { return sys.shapes[s].kind == ShapeKind::HalfSpace; };
    // a half-space against every shape of the other group: O(n)
    for (const int ia : C.shapes_a)
      if (plane(ia))
        for (const int ib : C.shapes_b)
          if (!plane(ib)) plane_pair(sys, d, spatial, k, sys.shapes[ia], sys.shapes[ib], visit);
    for (const int ib : C.shapes_b)
      if (plane(ib))
        for (const int ia : C.shapes_a)
          if (!plane(ia)) plane_pair(sys, d, spatial, k, sys.shapes[ib], sys.shapes[ia], visit);
    // spheres and capsules against spheres and capsules (a box meets half-spaces only: Model::add_contact)
    sa.clear(), sb.clear();
    const auto is_swept = [&](int s) { return sys.shapes[s].kind == ShapeKind::Sphere || sys.shapes[s].kind == ShapeKind::Capsule; };
    std::copy_if(C.shapes_a.begin(), C.shapes_a.end(), std::back_inserter(sa), is_swept);
    std::copy_if(C.shapes_b.begin(), C.shapes_b.end(), std::back_inserter(sb), is_swept);
    if (sa.size() * sb.size() > 64) {
      swept_groups(sys, d, spatial, k, sa, sb, visit);
    } else {  // a few pairs: each shape placed once, every pair tested
      thread_local std::vector<Swept> wb;
      wb.clear();
      for (const int ib : sb) wb.push_back(swept(sys, d, ib, 0));
      for (const int ia : sa) {
        const Swept wa = swept(sys, d, ia, 0);
        for (const Swept& w : wb) swept_pair(sys, d, spatial, k, wa, w, visit);
      }
    }
  }
}

double contact_gap(const System& sys, const Data& d, int k) {
  const Contact& C = sys.contacts[k];
  const auto plane = [&](int s) { return sys.shapes[s].kind == ShapeKind::HalfSpace; };
  double gap = std::numeric_limits<double>::infinity();
  // g = n·(x_B − o) − r_B of every feature of the other group's shapes against each half-space
  const auto against_plane = [&](const Shape& P, const Shape& O) {
    if (P.body == O.body) return;
    const Vec3 o = global(d, P.body, P.a), n = turned(d, P.body, P.n);
    shape_points(O, d, [&](const Vec3& x, double r) { gap = std::min(gap, n.dot(x - o) - r); });
  };
  for (const int ia : C.shapes_a)
    for (const int ib : C.shapes_b)
      if (plane(ia) != plane(ib)) plane(ia) ? against_plane(sys.shapes[ia], sys.shapes[ib])
                                            : against_plane(sys.shapes[ib], sys.shapes[ia]);
  // g = |p_B − p_A| − r_A − r_B of two swept spheres, from the closest points of their segments
  const auto pair_gap = [&](const Swept& A, const Swept& B) {
    if (sys.shapes[A.shape].body == sys.shapes[B.shape].body) return;
    double s = 0.0, t = 0.0;
    closest_points<double>(A.p0, A.p1, B.p0, B.p1, s, t);
    const Vec3 pa = A.p0 + s * (A.p1 - A.p0), pb = B.p0 + t * (B.p1 - B.p0);
    gap = std::min(gap, (pb - pa).norm() - A.radius - B.radius);
  };
  std::vector<Swept> wa, wb;
  double reach = 0.0;  // the largest radius: pairs whose extents along x lie farther apart have larger gaps
  for (const int s : C.shapes_a)
    if (!plane(s) && sys.shapes[s].kind != ShapeKind::Box) wa.push_back(swept(sys, d, s, 0)), reach = std::max(reach, wa.back().radius);
  for (const int s : C.shapes_b)
    if (!plane(s) && sys.shapes[s].kind != ShapeKind::Box) wb.push_back(swept(sys, d, s, 0)), reach = std::max(reach, wb.back().radius);
  if (wa.size() * wb.size() <= 4096) {
    for (const Swept& A : wa)
      for (const Swept& B : wb) pair_gap(A, B);
    return gap;
  }
  // many pairs: only those whose extents, widened by `reach`, meet (the others' gaps exceed reach): g = min(reach, ...)
  // is then the same continuous function, at O(n log n + pairs)
  std::vector<std::pair<const Swept*, bool>> all;
  for (const Swept& w : wa) all.push_back({&w, true});
  for (const Swept& w : wb) all.push_back({&w, false});
  std::sort(all.begin(), all.end(), [](const auto& x, const auto& y) { return x.first->lo < y.first->lo; });
  std::vector<const Swept*> open_a, open_b;
  for (const auto& [w, in_a] : all) {
    std::vector<const Swept*>& other = in_a ? open_b : open_a;
    other.erase(std::remove_if(other.begin(), other.end(), [&](const Swept* o) { return o->hi + reach < w->lo; }),
                other.end());
    for (const Swept* o : other) pair_gap(*w, *o);
    (in_a ? open_a : open_b).push_back(w);
  }
  return std::min(gap, reach);
}

Eigen::Matrix<double, 6, 24> contact_jacobian(const System& sys, const ContactForce& c) {
  Eigen::Matrix<AD, 24, 1> eps;
  for (int i = 0; i < 24; ++i) eps(i) = AD(0.0, 24, i);
  const Evaluated<AD> e = evaluate<AD>(c, *sys.contacts[c.contact].law, eps);
  const V3<AD> m = e.x.cross(e.f);
  Eigen::Matrix<double, 6, 24> J;
  for (int k = 0; k < 3; ++k) {
    J.row(k) = m(k).derivatives().transpose();
    J.row(k + 3) = e.f(k).derivatives().transpose();
  }
  return J;
}

double contact_energy(const System& sys, const Data& d) {
  double V = 0.0;
  for_each_contact_force(sys, d, false, [&](const ContactForce& c) { V += sys.contacts[c.contact].law->energy(-c.gap); });
  return V;
}

double contact_power(const System& sys, const Data& d) {
  double P = 0.0;
  for_each_contact_force(sys, d, false, [&](const ContactForce& c) {
    P += sys.contacts[c.contact].law->power(-c.gap, -c.gap_rate, c.Fn, c.f - c.Fn * c.n, c.vt);
  });
  return P;
}

}  // namespace rigidfem

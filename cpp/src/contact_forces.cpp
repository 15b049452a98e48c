#include "rigidfem/contact_forces.hpp"

#include <cmath>
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

void for_each_contact_force(const System& sys, const Data& d, bool spatial,
                            const std::function<void(const ContactForce&)>& visit) {
  for (int k = 0; k < static_cast<int>(sys.contacts.size()); ++k) {
    const Contact& C = sys.contacts[k];
    for (const int ia : C.shapes_a)
      for (const int ib : C.shapes_b) {
        const Shape *A = &sys.shapes[ia], *B = &sys.shapes[ib];
        if (A->body == B->body) continue;
        if (B->kind == ShapeKind::HalfSpace) std::swap(A, B);  // the half-space is a's
        ContactForce c;
        c.contact = k, c.body_a = A->body, c.body_b = B->body;
        c.Va = body_velocity(d, A->body, spatial), c.Vb = body_velocity(d, B->body, spatial);
        if (A->kind == ShapeKind::HalfSpace) {
          c.plane = true;
          c.p[0] = global(d, A->body, A->a), c.p[1] = turned(d, A->body, A->n);
          shape_points(*B, d, [&](const Vec3& x, double r) {
            c.p[2] = x, c.rb = r;
            if (c.p[1].dot(x - c.p[0]) - r < 0.0 && overlap(c, *C.law, d.t)) visit(c);
          });
          continue;
        }
        // two swept spheres: the segments' bounding spheres first
        c.p[0] = global(d, A->body, A->a), c.p[1] = global(d, A->body, A->kind == ShapeKind::Capsule ? A->b : A->a);
        c.p[2] = global(d, B->body, B->a), c.p[3] = global(d, B->body, B->kind == ShapeKind::Capsule ? B->b : B->a);
        c.ra = A->radius, c.rb = B->radius;
        const double reach = 0.5 * ((c.p[1] - c.p[0]).norm() + (c.p[3] - c.p[2]).norm()) + c.ra + c.rb;
        if ((0.5 * (c.p[0] + c.p[1] - c.p[2] - c.p[3])).norm() < reach && overlap(c, *C.law, d.t)) visit(c);
      }
  }
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

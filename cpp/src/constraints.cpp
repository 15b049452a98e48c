#include "rigidfem/constraints.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "rigidfem/errors.hpp"

namespace rigidfem {

namespace {

using Mat3X = Eigen::Matrix<double, 3, Eigen::Dynamic>;

/// A vector quantity x(q, t) fixed in a body: its value, rate, second rate at q̈_free = 0, and
/// ∂x/∂q (3, nc) over all coordinates.
struct Track {
  Vec3 x, xd, xdd;
  Mat3X J;
};

/// Column h of frame P = T_p F in body p (h = 0..2: an axis, 3: the origin) with its rates and its
/// Jacobian ∂x/∂q_i = Σ_u U_u x̃ over the uses u on the path from p to the ground (x̃ = (x, 1)
/// for the origin, (x, 0) for an axis): the Lagrange formulation's kinematics (T, Ṫ, T̈, U), which
/// also holds the linear joints. The ground (p = −1): F itself, at rest.
void homogeneous_track(const System& sys, const Data& d, int p, const Mat4& F, int h, Track& tr) {
  tr.J.setZero(3, sys.nc);
  const Eigen::Vector4d c = F.col(h);
  tr.x = (d.T[p] * c).head<3>();
  tr.xd = (d.Td[p] * c).head<3>();
  tr.xdd = (d.Tdd[p] * c).head<3>();
  const Eigen::Vector4d xh(tr.x(0), tr.x(1), tr.x(2), c(3));
  for (int k = p; k >= 0; k = sys.parent[k])
    for (int u = sys.use_start[k]; u < sys.use_start[k + 1]; ++u)
      tr.J.col(sys.use_coord[u]) += (d.U[u] * xh).head<3>();
}

/// The spatial velocity v_p and the acceleration a_p at q̈_free = 0 (the prescribed q̈ in, no
/// gravity) of body p from the axes s_u = (ω_u, v_u) of the uses on its path, walked from p to the
/// ground (last use first) with w = Σ s q̇ over the uses already passed (those after u):
///   v_p = Σ_u s_u q̇_u,  a_p = Σ_u (s_u q̈_u + ṡ_u q̇_u) = Σ_u (s_u q̈_u + (s_u q̇_u) ×m w),
/// since ṡ_u = v_before(u) ×m s_u and the sum over the pairs u' < u reads the same either way.
std::pair<Vec6, Vec6> body_motion(const System& sys, const Data& d, int p) {
  Vec6 w = Vec6::Zero(), a = Vec6::Zero();
  for (int k = p; k >= 0; k = sys.parent[k])
    for (int u = sys.use_start[k + 1] - 1; u >= sys.use_start[k]; --u) {
      const int i = sys.use_coord[u];
      const Vec6 sqd = d.axes[u] * d.qda(i);
      a += d.axes[u] * d.qdda(i) + crossm(sqd, w);
      w += sqd;
    }
  return {w, a};
}

/// The same from the recursive algorithms' kinematics (T and the axes: frames_and_axes), with the
/// body's motion (ω, v_O), (α, a_O) from body_motion:
///   origin x: ẋ = v_O + ω × x, ẍ = a_O + α × x + ω × ẋ, ∂x/∂q_u = ω_u × x + v_u;
///   axis e:   ė = ω × e,       ë = α × e + ω × ė,       ∂e/∂q_u = ω_u × e.
void spatial_track(const System& sys, const Data& d, int p, const std::pair<Vec6, Vec6>& motion, const Mat4& F,
                   int h, Track& tr) {
  tr.J.setZero(3, sys.nc);
  const bool point = h == 3;
  tr.x = (d.T[p] * F.col(h)).head<3>();
  const auto& [v, a] = motion;
  tr.xd = v.head<3>().cross(tr.x) + (point ? Vec3(v.tail<3>()) : Vec3::Zero());
  tr.xdd = a.head<3>().cross(tr.x) + v.head<3>().cross(tr.xd) + (point ? Vec3(a.tail<3>()) : Vec3::Zero());
  for (int k = p; k >= 0; k = sys.parent[k])
    for (int u = sys.use_start[k]; u < sys.use_start[k + 1]; ++u) {
      const Vec6& s = d.axes[u];
      tr.J.col(sys.use_coord[u]) += s.head<3>().cross(tr.x) + (point ? Vec3(s.tail<3>()) : Vec3::Zero());
    }
}

/// The columns h of frame F in body p whose bit 1 << h is in `columns` (0..2: the axes, 3: the origin) as
/// tracks, from the spatial kinematics or the 4x4 ones. Into tr, whose Jacobians keep their storage from call
/// to call (the loops' rows allocate nothing once sized).
void frame_tracks(const System& sys, const Data& d, int p, const Mat4& F, unsigned columns, bool spatial,
                  std::array<Track, 4>& tr) {
  const auto motion = spatial && p >= 0 ? body_motion(sys, d, p) : std::pair<Vec6, Vec6>{};
  for (int h = 0; h < 4; ++h) {
    if (!(columns & (1u << h))) continue;
    if (p < 0) {  // the ground: F itself, at rest
      tr[h].x = F.block<3, 1>(0, h), tr[h].xd.setZero(), tr[h].xdd.setZero();
      tr[h].J.setZero(3, sys.nc);
    } else if (spatial) {
      spatial_track(sys, d, p, motion, F, h, tr[h]);
    } else {
      homogeneous_track(sys, d, p, F, h, tr[h]);
    }
  }
}

/// d = r_B − r_A as a track, into out.
void difference(const Track& b, const Track& a, Track& out) {
  out.x = b.x - a.x, out.xd = b.xd - a.xd, out.xdd = b.xdd - a.xdd;
  out.J = b.J - a.J;
}

enum { X, Y, Z };

/// A loop kind's row of the table: its name, what it leaves free, and (not Distance) its rows: position rows d·a_i
/// for the axes i of A in `positions` (the origins' difference d held along them), then direction rows b_j·a_i for
/// each pair (j, i) (B's axis j held square to A's axis i).
struct KindRow {
  LoopKind kind;
  const char* name;
  const char* doc;
  std::vector<int> positions;
  std::vector<std::pair<int, int>> directions;
  /// The columns of frames A and B (bits 1 << h, h = 3 the origin) that its rows read.
  std::pair<unsigned, unsigned> columns() const {
    if (kind == LoopKind::Distance) return {8u, 8u};
    unsigned a = positions.empty() ? 0u : 8u, b = a;
    for (int i : positions) a |= 1u << i;
    for (const auto& [j, i] : directions) b |= 1u << j, a |= 1u << i;
    return {a, b};
  }
};

const std::vector<KindRow>& kind_table() {
  static const std::vector<KindRow> table = {
      {LoopKind::Revolute, "revolute", "rotation about the common z axis", {X, Y, Z}, {{Z, X}, {Z, Y}}},
      {LoopKind::Spherical, "spherical", "every rotation about the common origin", {X, Y, Z}, {}},
      {LoopKind::Universal, "universal", "rotations about A's x axis and B's y axis (the cross)", {X, Y, Z}, {{Y, X}}},
      {LoopKind::Prismatic, "prismatic", "translation along z", {X, Y}, {{Z, X}, {Z, Y}, {X, Y}}},
      {LoopKind::Cylindrical, "cylindrical", "translation along and rotation about z", {X, Y}, {{Z, X}, {Z, Y}}},
      {LoopKind::Fixed, "fixed", "none", {X, Y, Z}, {{Z, X}, {Z, Y}, {X, Y}}},
      {LoopKind::Planar, "planar", "translation in the x–y plane and rotation about z", {Z}, {{Z, X}, {Z, Y}}},
      {LoopKind::Distance, "distance", "everything but the distance |r_B − r_A| = l", {}, {}},
  };
  return table;
}

const KindRow& layout(LoopKind kind) {
  const KindRow& row = kind_table()[static_cast<int>(kind)];  // the table in the enum's order
  if (row.kind != kind) throw std::logic_error("kind_table: a row out of the enum's order");
  return row;
}

/// Row r of the constraints: value, rate, −(second rate at q̈_free = 0); its Jacobian the caller writes into d.G.
void put(Data& d, int r, double g, double gd, double bias) {
  d.g(r) = g;
  d.gd(r) = gd;
  d.gamma(r) = -bias;
}

/// g = x·y: ġ = ẋ·y + x·ẏ, g̈ = ẍ·y + 2 ẋ·ẏ + x·ÿ, ∂g/∂q = yᵀ ∂x/∂q + xᵀ ∂y/∂q.
void dot_row(Data& d, int r, const Track& x, const Track& y) {
  put(d, r, x.x.dot(y.x), x.xd.dot(y.x) + x.x.dot(y.xd), x.xdd.dot(y.x) + 2.0 * x.xd.dot(y.xd) + x.x.dot(y.xdd));
  d.G.row(r).noalias() = y.x.transpose() * x.J;
  d.G.row(r).noalias() += x.x.transpose() * y.J;
}

/// g = |x| − l(t): ġ = x·ẋ/|x| − l̇, g̈ = (ẋ·ẋ + x·ẍ)/|x| − (x·ẋ)²/|x|³ − l̈, ∂g/∂q = xᵀ ∂x/∂q / |x|.
void distance_row(Data& d, int r, const Track& x, const MotionState& l, const std::string& name) {
  const double n = x.x.norm();
  if (!(n > 1e-12 * std::max(1.0, std::abs(l.q))))
    throw SimulationError(d.t, "the distance of loop '" + name + "' is zero, where its direction is undefined");
  const double s = x.x.dot(x.xd);
  put(d, r, n - l.q, s / n - l.qd, (x.xd.squaredNorm() + x.x.dot(x.xdd)) / n - s * s / (n * n * n) - l.qdd);
  d.G.row(r).noalias() = (x.x / n).transpose() * x.J;
}

}  // namespace

void constraint_equations(const System& sys, Data& d, bool spatial) {
  for (std::size_t k = 0; k < sys.loops.size(); ++k) {
    const Loop& L = sys.loops[k];
    int r = sys.loop_row[k];
    // The origins (columns 3) and the axes (columns 0..2) of frames A and B that the kind's rows read.
    const KindRow& rows = layout(L.kind);
    const auto [columns_a, columns_b] = rows.columns();
    // the frames' tracks in a workspace of this thread, sized once for the system's coordinates
    thread_local std::array<Track, 4> a, b;
    thread_local Track dr;
    frame_tracks(sys, d, L.body_a, L.frame_a, columns_a, spatial, a);
    frame_tracks(sys, d, L.body_b, L.frame_b, columns_b, spatial, b);
    if (columns_a & 8u) difference(b[3], a[3], dr);
    if (L.kind == LoopKind::Distance) {
      const MotionState l = L.drive ? L.drive->at(d.t) : MotionState{L.length, 0.0, 0.0};
      if (!std::isfinite(l.q) || !std::isfinite(l.qd) || !std::isfinite(l.qdd))
        throw SimulationError(d.t, "the length drive of loop '" + L.name + "' returned NaN or inf");
      distance_row(d, r, dr, l, L.name);
      continue;
    }
    for (int i : rows.positions) dot_row(d, r++, dr, a[i]);
    for (const auto& [j, i] : rows.directions) dot_row(d, r++, b[j], a[i]);
  }
}

VecX least_norm(const MatX& A, const VecX& b) {
  // x = V Σ⁺ Uᵀ b with σ_i⁺ = 1/σ_i for σ_i > 1e-10 σ_max, else 0. A = G S⁻¹ Gᵀ goes as G's squared
  // singular values: G's rows count as dependent below 1e-5 of its largest, at the acceleration level
  // and in the projection alike (project_onto_loops solves with the same A = G M⁻¹ Gᵀ). The SVD's
  // singular values, unlike a pivoted QR's diagonal, pass smoothly through the threshold as G's rank
  // changes on a singular position.
  Eigen::JacobiSVD<MatX> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const VecX& s = svd.singularValues();
  const double floor = s.size() > 0 ? 1e-10 * s(0) : 0.0;
  VecX c = svd.matrixU().transpose() * b;
  for (Eigen::Index i = 0; i < s.size(); ++i) c(i) = s(i) > floor ? c(i) / s(i) : 0.0;
  return svd.matrixV() * c;
}

void row_basis(const MatX& G, MatX& B) {
  Eigen::JacobiSVD<MatX> svd(G, Eigen::ComputeThinU);
  const VecX& s = svd.singularValues();
  Eigen::Index r = 0;
  while (r < s.size() && s(r) > 1e-5 * s(0)) ++r;
  B = svd.matrixU().leftCols(r);
}

namespace {

/// What a rank kept from the loops (least_norm_symmetric's `rank`) may leave out: directions summing to at most
/// this fraction of tr A (on the Bricard linkage, a stage about 5e-3 rad off the loops).
constexpr double kept_rank_slack = 1e-6;

using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 8, 8>;  // a few loop rows, on the stack
using SmallV = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 8, 1>;

/// (LᵀL)⁻¹ of the Gram matrix C = LᵀL (r × r, r <= 8) as Mᵀ M from its Cholesky factor C = K Kᵀ, M = K⁻¹ (lower);
/// false unless C is positive definite with cond₂(C) < 1e6, which the bound cond₂(C) = cond₂(K)² <=
/// (‖K‖_F ‖M‖_F)² guarantees without an estimator's extra solves.
bool gram_inverse(const Small& C, Small& Cinv) {
  const Eigen::Index r = C.rows();
  const Eigen::LLT<Small> llt(C);
  if (llt.info() != Eigen::Success) return false;
  const Small K = llt.matrixL();
  Small M = Small::Zero(r, r);
  // M = K⁻¹ column by column: M_jj = 1/K_jj, M_ij = −(Σ_{j<=k<i} K_ik M_kj) / K_ii
  for (Eigen::Index j = 0; j < r; ++j) {
    M(j, j) = 1.0 / K(j, j);
    for (Eigen::Index i = j + 1; i < r; ++i) M(i, j) = -K.row(i).segment(j, i - j).dot(M.col(j).segment(j, i - j)) / K(i, i);
  }
  const double bound = K.squaredNorm() * M.squaredNorm();
  if (!(bound < 1e6)) return false;
  Cinv.noalias() = M.transpose() * M;
  return true;
}

/// x = A⁺ b (n <= 8) by a diagonally pivoted Cholesky factor P A Pᵀ = L Lᵀ (L: n × r) where A's spectrum has a
/// clear gap: the Schur complement left after r pivots has a trace <= 1e-14 tr A (the round-off of exact
/// dependencies: a Bricard linkage's redundant row, a planar loop's rows out of its plane) and LᵀL, whose
/// eigenvalues are A's r others, a condition bound below 1e6 (gram_inverse; a cond₂ of 1e6/r² may already fail it). The eigenvalue floor of
/// least_norm_symmetric (1e-10 λ_max) keeps those r and drops the rest, and then A⁺ = Pᵀ L (LᵀL)⁻² Lᵀ P.
/// With `rank` >= 0 it stops after that many pivots and accepts a Schur complement up to kept_rank_slack tr A. Returns
/// r, or -1 where the gap is not that clear.
int pseudo_inverse_by_pivots(const MatX& A, const VecX& b, VecX& x, int rank) {
  const Eigen::Index n = A.rows();
  Small W = A.selfadjointView<Eigen::Lower>(), L = Small::Zero(n, n);
  Eigen::Matrix<Eigen::Index, Eigen::Dynamic, 1, 0, 8, 1> p(n);
  for (Eigen::Index i = 0; i < n; ++i) p(i) = i;
  const double trace = W.trace();
  if (!(trace >= 0.0) || !std::isfinite(trace)) return -1;
  const Eigen::Index cap = rank >= 0 ? std::min<Eigen::Index>(rank, n) : n;
  Eigen::Index r = 0;
  for (; r < cap; ++r) {
    Eigen::Index j;
    const double pivot = W.diagonal().tail(n - r).maxCoeff(&j);
    if (!(pivot > 1e-14 * trace)) break;
    j += r;
    if (j != r) {  // the pivot's row and column to position r
      W.row(r).swap(W.row(j)), W.col(r).swap(W.col(j)), L.row(r).swap(L.row(j)), std::swap(p(r), p(j));
    }
    // L_kr = W_kr / √W_rr (k >= r), W_kl −= L_kr L_lr on the rest
    L.col(r).tail(n - r) = W.col(r).tail(n - r) / std::sqrt(pivot);
    W.bottomRightCorner(n - r - 1, n - r - 1).noalias() -= L.col(r).tail(n - r - 1) * L.col(r).tail(n - r - 1).transpose();
  }
  // the Schur complement left, entry by entry (its diagonal alone bounds it only where A is semi-definite)
  const double left = r < n ? W.bottomRightCorner(n - r, n - r).cwiseAbs().sum() : 0.0;
  if (!(left <= (r == cap && cap < n ? kept_rank_slack : 1e-14) * trace)) return -1;
  SmallV bp(n);  // P b, read before x is written (x may be b)
  for (Eigen::Index i = 0; i < n; ++i) bp(i) = b(p(i));
  if (r == 0) {  // A = 0
    x.setZero(n);
    return 0;
  }
  const auto B = L.leftCols(r);
  Small Ginv;
  if (!gram_inverse(Small(B.transpose() * B), Ginv)) return -1;
  const SmallV xp = B * (Ginv * (Ginv * (B.transpose() * bp)));
  x.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) x(p(i)) = xp(i);
  return x.allFinite() ? static_cast<int>(r) : -1;
}

}  // namespace

int least_norm_symmetric(const MatX& A, const VecX& b, Eigen::SelfAdjointEigenSolver<MatX>& eigen, VecX& c,
                         VecX& x, int rank) {
  if (A.rows() <= 8) {
    const int r = pseudo_inverse_by_pivots(A, b, x, rank);
    if (r >= 0) return r;
  }
  // x = V Λ⁺ Vᵀ b, A = V Λ Vᵀ (the lower triangle read), λ_i⁺ = 1/λ_i for λ_i > 1e-10 λ_max, else 0
  // (a negative λ_i is round-off of a zero one); with `rank`, 0 also for all but the `rank` largest where
  // those sum to at most kept_rank_slack tr A.
  eigen.compute(A);
  const VecX& s = eigen.eigenvalues();  // ascending
  double floor = s.size() > 0 ? 1e-10 * s(s.size() - 1) : 0.0;
  const Eigen::Index drop = rank >= 0 ? s.size() - std::min<Eigen::Index>(rank, s.size()) : 0;
  if (drop > 0 && s.head(drop).cwiseAbs().sum() <= kept_rank_slack * s.sum()) floor = std::max(floor, s(drop - 1));
  c.noalias() = eigen.eigenvectors().transpose() * b;
  int kept = 0;
  for (Eigen::Index i = 0; i < s.size(); ++i) {
    c(i) = s(i) > floor ? c(i) / s(i) : 0.0;
    kept += s(i) > floor;
  }
  x.noalias() = eigen.eigenvectors() * c;
  return kept;
}

VecX least_norm_symmetric(const MatX& A, const VecX& b, int rank) {
  Eigen::SelfAdjointEigenSolver<MatX> eigen(A.rows());
  VecX c, x;
  least_norm_symmetric(A, b, eigen, c, x, rank);
  return x;
}

MatX free_jacobian(const System& sys, const Data& d) { return d.G(Eigen::all, sys.free_coords); }

RowMatX loop_reactions(const System& sys, const Data& d, const VecX& lambda) {
  RowMatX W = RowMatX::Zero(static_cast<Eigen::Index>(sys.loops.size()), 6);
  for (std::size_t k = 0; k < sys.loops.size(); ++k) {
    const Loop& L = sys.loops[k];
    const int r0 = sys.loop_row[k];
    const Mat4 PA = (L.body_a < 0 ? Mat4::Identity() : d.T[L.body_a]) * L.frame_a;
    const Mat4 PB = (L.body_b < 0 ? Mat4::Identity() : d.T[L.body_b]) * L.frame_b;
    const Mat3 RA = PA.topLeftCorner<3, 3>(), RB = PB.topLeftCorner<3, 3>();
    if (L.kind == LoopKind::Distance) {
      W(k, 0) = lambda(r0);
      continue;
    }
    // Force Σ λ_i a_i at B's origin from the position rows; torque Σ λ b_j × a_i from the rest.
    const KindRow& rows = layout(L.kind);
    Vec3 F = Vec3::Zero(), tau = Vec3::Zero();
    int r = r0;
    for (int i : rows.positions) F += lambda(r++) * RA.col(i);
    for (const auto& [j, i] : rows.directions) tau += lambda(r++) * RB.col(j).cross(RA.col(i));
    W.row(k).head<3>() = RA.transpose() * F;
    W.row(k).tail<3>() = RA.transpose() * tau;
  }
  return W;
}

int loop_rows(LoopKind kind) {
  if (kind == LoopKind::Distance) return 1;
  const KindRow& rows = layout(kind);
  return static_cast<int>(rows.positions.size() + rows.directions.size());
}

const char* loop_kind_name(LoopKind kind) { return layout(kind).name; }

const char* loop_kind_doc(LoopKind kind) { return layout(kind).doc; }

LoopKind parse_loop_kind(const std::string& name, const std::string& argument) {
  std::string names;
  for (const KindRow& row : kind_table()) {
    if (name == row.name) return row.kind;
    names += std::string(names.empty() ? "" : ", ") + row.name;
  }
  bad(argument, "one of " + names, "'" + name + "'");
}

}  // namespace rigidfem

/// The compiled, immutable multibody system, its workspace and the tree helpers every engine uses.
///
/// System holds topology (bodies in order parent[p] < p), constant placements B_p,
/// pseudo-inertias H_p and flat coordinate tables. Every scratch array lives in
/// Data, so one System may be used by several threads, each with its own Data.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "rigidfem/model.hpp"

namespace rigidfem {

/// One joint coordinate of the compiled system ("all coordinates": free and prescribed).
struct Coordinate {
  int body = -1;           ///< body whose joint it belongs to
  int slot = 0;            ///< position within that joint
  Axis axis = Axis::X;
  int free_index = -1;     ///< index in q (free coordinates) or −1
  int drive_index = -1;    ///< index in the prescribed list or −1
  SpringDamping spring;    ///< its own spring, damper and constant applied force (coordinate_laws.hpp)
  std::vector<std::shared_ptr<const CoordinateLaw>> laws;  ///< further laws (a Python function, friction)
  ProfilePtr drive;        ///< prescribed motion, or null
  /// The ropes wound on it (a drum, a sheave's slip): (element, winding) pairs; it takes r P c of each.
  std::vector<std::pair<int, int>> windings;
  std::string name;        ///< "body.rz"
};

/// A compiled Maxwell arm (model.hpp): its coordinate (index in coords and in q), k and τ.
struct Arm {
  int coord = -1, q = -1;
  double stiffness = 0.0, tau = 0.0;  ///< k (N/m or N·m/rad), τ (s)
};

/// How the equations of motion are evaluated.
enum class Algorithm { Lagrange, Recursive };

/// Made by Model::compile as a shared object (weak_from_this identifies it, e.g. to the
/// workspaces the bindings keep per thread).
class System : public std::enable_shared_from_this<System> {
 public:
  /// Recursive (O(n), the default) or the book's Lagrange formulation; systems with linear
  /// joints always use Lagrange.
  Algorithm algorithm = Algorithm::Lagrange;
  int nbodies = 0;
  int nq = 0;  ///< free coordinates (the unknowns)
  int np = 0;  ///< prescribed coordinates
  int nc = 0;  ///< all joint coordinates, nq + np

  std::vector<std::string> body_names;  // (nbodies)
  std::vector<int> parent;              // (nbodies), −1 = ground, parent[p] < p
  std::vector<Mat4> B;                  // (nbodies) 4x4 joint placement in the parent frame
  std::vector<char> shift_only;         // (nbodies) B's rotation is exactly the identity
  std::vector<Mat4> H;                  // (nbodies) 4x4 pseudo-inertia, body frame
  std::vector<double> mass;             // (nbodies)
  std::vector<Vec3> com;                // (nbodies) centre of mass, body frame
  std::vector<Mat3> inertia;            // (nbodies) inertia tensor about the centre of mass, body axes
  std::vector<Joint> joint;             // (nbodies)
  std::vector<int> coord_start;         // (nbodies + 1) first coordinate of body p in `coords`
  std::vector<Coordinate> coords;       // (nc) in body order, within a joint in the book's order
  std::vector<int> free_coords;         // (nq) -> index in coords
  std::vector<int> drive_coords;        // (np) -> index in coords
  // The free coordinates of body p are contiguous in q (Pinocchio's idx_v, nv):
  std::vector<int> q_index;             // (nbodies) first free coordinate of body p in q
  std::vector<int> nq_of;               // (nbodies) number of free coordinates of body p
  std::vector<int> q_use;               // (nq) the use (axis) of free coordinate k on its own body
  std::vector<char> ball;               // (nbodies) three free rotations (a spherical joint, an sde's three
                                        // rotations), after any prescribed translation: axes through one point
  // Coordinate uses: the coordinates that move each body's joint, its own ones first
  // (so without couplings use u is coordinate u), then coupled ones (linear model).
  int nuses = 0;
  std::vector<int> use_start;           // (nbodies + 1) first use of body p
  std::vector<int> use_coord;           // (nuses) -> index in coords
  std::vector<Axis> use_axis;           // (nuses) its elementary motion
  std::vector<Mat4> use_G;              // (nuses) its generator in the joint frame
  std::vector<int> use_q;               // (nuses) index in q of its coordinate, −1 if prescribed
  std::vector<int> use_drive;           // (nuses) index among the prescribed coordinates, −1 if free
  int max_uses = 0;                     // largest number of uses of one body
  std::vector<int> zyx_pitch;           // coordinate index of φ2 in every exact joint with φ3, φ2 and φ1
  Vec3 gravity = Vec3::Zero();          // m/s², global
  std::vector<Load> loads;
  // Loop closures: constraint rows loop_row[k] .. loop_row[k + 1] − 1 of g(q, t) = 0.
  std::vector<Loop> loops;
  std::vector<int> loop_row;            // (nloops + 1)
  int nl = 0;                           ///< constraint rows (multipliers λ)
  std::vector<Flow> flows;              // links of varying length (flows.hpp)
  std::vector<ForceElement> elements;   // force elements between two bodies (force_elements.hpp)
  std::vector<Shape> shapes;            // shapes fixed on bodies, and the contacts between them (contact.hpp)
  std::vector<Contact> contacts;
  std::vector<Arm> arms;                // (nz) Maxwell arms, in coordinate order (arms.hpp)
  int nz = 0;                           ///< internal variables: the arms' forces s

  std::vector<std::string> coordinate_names() const;  ///< (nq)
  std::vector<std::string> prescribed_names() const;  ///< (np)
};

/// The use of coordinate i (index in coords) on its own body: its axis in Data::axes and U.
inline int own_use(const System& sys, int i) { return sys.use_start[sys.coords[i].body] + sys.coords[i].slot; }

/// The uses that move body p's joint, for joint_motion and joint_frames.
inline JointUses joint_uses(const System& sys, int p) {
  const int u0 = sys.use_start[p];
  return {sys.use_start[p + 1] - u0, sys.use_coord.data() + u0, sys.use_axis.data() + u0, sys.use_G.data() + u0,
          sys.joint[p].linear};  // data() + u0: defined also for no uses
}

/// X_parent(p), or `root` for a body on the ground.
template <class T>
const T& parent_value(const System& sys, const std::vector<T>& X, int p, const T& root) {
  return sys.parent[p] >= 0 ? X[sys.parent[p]] : root;
}

/// X̄_p = X_p + Σ_children X̄_c: sums a per-body quantity over subtrees, children before parents.
template <class T>
void accumulate_subtrees(const System& sys, std::vector<T>& X) {
  for (int p = sys.nbodies - 1; p >= 0; --p)
    if (sys.parent[p] >= 0) X[sys.parent[p]] += X[p];
}

/// Throws std::invalid_argument unless `body` indexes a body of sys (−1, the ground, if allowed).
void check_body(const System& sys, int body, const std::string& argument, bool ground_allowed = false);

/// The motion subspace S (6, ≤ 6) of a body's free coordinates.
using Subspace = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6>;

/// Workspace of the algorithms. "(nbodies) 4x4" are global quantities.
struct Data {
  explicit Data(const System& sys);
  double t = 0.0;
  double load_factor = 1.0;    // input: scales gravity, loads and applied generalised forces (load stepping)
  VecX qa, qda, qdda;          // (nc) all coordinates: value, rate, acceleration
  std::vector<Mat4> T;         // (nbodies) 4x4 T_p, pose of body p in the global frame
  std::vector<Mat4> Td, Tdd;   // (nbodies) 4x4 Ṫ_p, T̈_p
  std::vector<Mat4> U;         // (nuses) 4x4 U_u with ∂T_k/∂q_i = U_u T_k for the bodies k below the use u of q_i
  std::vector<Mat4> X;         // (max_uses) scratch of jcalc: local twists (∂T̃/∂q) T̃⁻¹
  std::vector<Mat4> Hbar;      // (nbodies) Σ_{k in subtree(p)} T_k H_k T_kᵀ
  std::vector<Mat4> Wbar;      // (nbodies) Σ_{k in subtree(p)} T_k H_k T̈_kᵀ  (inertia)
  std::vector<Mat4> Zbar;      // (nbodies) Σ_{k in subtree(p)} load moments   (gravity, forces)
  MatX A;                      // (nq, nq) mass matrix, allocated by the first mass_matrix (ABA needs none)
  VecX f;                      // (nq) right-hand side: loads − velocity terms − springs − dampers
  VecX qdd;                    // (nq)
  VecX tau;                    // (np) driving forces of the prescribed coordinates
  VecX arm_force;              // (nc) input: Σ s of each coordinate's Maxwell arms (zero: relaxed; arms.hpp)
  Eigen::LLT<MatX> llt;
  // Loop closures (constraints.hpp):
  VecX g, gd, gamma;           // (nl) g(q, t), ġ, and γ with G q̈ = γ
  MatX G;                      // (nl, nc) ∂g/∂q over all coordinates
  VecX lambda;                 // (nl) multipliers of the last constrained forward dynamics
  // close_loops' workspace (no allocation per call): G over the free coordinates, Y = M⁻¹ Gᵀ, G Y, the
  // right-hand side γ − G q̈, a column, and the eigensolver of G Y, sized at construction
  MatX Gfree, Y, GY;
  VecX loop_rhs, loop_col, loop_c;
  Eigen::SelfAdjointEigenSolver<MatX> loop_eigen;
  int loop_rank = -1;          // rank of G M⁻¹Gᵀ kept at the last project_and_forward_dynamics' projected state, which
                               // the forward dynamics keep to until the next one (a step's stages; -1: none)
  // Recursive algorithms (ground coordinates, at the global origin):
  std::vector<Vec6> axes;      // (nuses) coordinate axes s = (ω, v_O)
  std::vector<Vec6> v, c, a;   // (nbodies) spatial velocity, joint bias acceleration, acceleration
  std::vector<Vec6> sf, pA;    // (nbodies) spatial force (subtree sums after RNEA), articulated bias force
  std::vector<Mat6> I, IA;     // (nbodies) spatial inertia, composite or articulated inertia
  std::vector<Vec6> fext;      // (nbodies) external loads
  std::vector<Subspace> S;     // (nbodies) axes of the free coordinates
  std::vector<Subspace> U6;    // (nbodies) I^A S
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>> Dinv;  // (nbodies) (Sᵀ I^A S)⁻¹
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>> u;    // (nbodies) τ − Sᵀ p^A
  // Mass properties and spring scales at t: the System's, but for the rfes of links of varying
  // length (flows.hpp), which set_state updates with L(t).
  std::vector<Mat4> H;         // (nbodies) 4x4 pseudo-inertia, body frame
  std::vector<double> mass;    // (nbodies)
  std::vector<Vec3> com;       // (nbodies)
  std::vector<Mat3> inertia;   // (nbodies) about the centre of mass, body axes
  VecX spring_scale;           // (nc) factor of each coordinate's stiffness and damping (L₀/L for sdes)
  std::vector<MotionState> flow;  // (nflows) L, v = L̇, v̇ at t (zero rates at rest)
  bool state_ok = true;        // false after a set_state that raised (it leaves a half-written state)
};

/// Throws std::invalid_argument unless d is a workspace made for sys (a Data of another system
/// would be written out of bounds).
void check_data(const System& sys, const Data& d);
/// check_data, and std::invalid_argument if the last set_state on d raised (the stages after it
/// would compute from a half-written state). A fresh workspace holds the zero state.
void check_state(const System& sys, const Data& d);

}  // namespace rigidfem

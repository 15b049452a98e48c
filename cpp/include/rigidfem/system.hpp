/// The compiled, immutable multibody system and its workspace.
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
  double stiffness = 0.0, rest = 0.0, damping = 0.0;
  double force = 0.0;      ///< constant applied generalised force
  ForceLaw force_law;      ///< optional Q(t, q, q̇)
  ProfilePtr drive;        ///< prescribed motion, or null
  std::string name;        ///< "body.rz"
};

/// How the equations of motion are evaluated.
enum class Algorithm { Lagrange, Recursive };

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

class System {
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
  std::vector<std::vector<int>> children;  // (nbodies)
  std::vector<Mat4> B;                  // (nbodies) 4x4 joint placement in the parent frame
  std::vector<Mat4> H;                  // (nbodies) 4x4 pseudo-inertia, body frame
  std::vector<double> mass;             // (nbodies)
  std::vector<Vec3> com;                // (nbodies) centre of mass, body frame
  std::vector<Mat3> inertia;            // (nbodies) inertia tensor about the centre of mass, body axes
  std::vector<Joint> joint;             // (nbodies)
  std::vector<int> coord_start;         // (nbodies + 1) first coordinate of body p in `coords`
  std::vector<Coordinate> coords;       // (nc) in body order, within a joint in the book's order
  std::vector<int> free_coords;         // (nq) -> index in coords
  std::vector<int> drive_coords;        // (np) -> index in coords
  // Coordinate uses: the coordinates that move each body's joint, its own ones first
  // (so without couplings use u is coordinate u), then coupled ones (linear model).
  int nuses = 0;
  std::vector<int> use_start;           // (nbodies + 1) first use of body p
  std::vector<int> use_coord;           // (nuses) -> index in coords
  std::vector<Mat4> use_G;              // (nuses) generator in the joint frame (linear joints)
  int max_uses = 0;                     // largest number of uses of one body
  std::vector<int> zyx_pitch;           // coordinate index of φ2 in every exact joint with φ3, φ2 and φ1
  Vec3 gravity = Vec3::Zero();          // m/s², global
  std::vector<Load> loads;

  std::vector<std::string> coordinate_names() const;  ///< (nq)
  std::vector<std::string> prescribed_names() const;  ///< (np)
};

/// The use of coordinate i (index in coords) on its own body: its axis in Data::axes and U.
inline int own_use(const System& sys, int i) { return sys.use_start[sys.coords[i].body] + sys.coords[i].slot; }

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
  Eigen::LLT<MatX> llt;
  // Recursive algorithms (ground coordinates, at the global origin):
  std::vector<Vec6> axes;      // (nuses) coordinate axes s = (ω, v_O)
  std::vector<Vec6> v, c, a;   // (nbodies) spatial velocity, joint bias acceleration, acceleration
  std::vector<Vec6> sf, pA;    // (nbodies) spatial force (subtree sums after RNEA), articulated bias force
  std::vector<Mat6> I, IA;     // (nbodies) spatial inertia, composite or articulated inertia
  std::vector<Vec6> fext;      // (nbodies) external loads
  std::vector<Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6>> U6;   // (nbodies) I^A S
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>> Dinv;  // (nbodies) (Sᵀ I^A S)⁻¹
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>> u;    // (nbodies) τ − Sᵀ p^A
};

}  // namespace rigidfem

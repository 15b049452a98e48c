/// Loop closures: joints that close a kinematic loop between two bodies, and length actuators
/// (book ch. 2.6 and 7.3). Each adds constraint equations g(q, t) = 0 to the tree's equations,
///   M q̈ = f + Gᵀλ,  g(q, t) = 0,  G = ∂g/∂q,
/// with the multipliers λ the loop's reactions (constraints.hpp evaluates g, G and the rest).
#pragma once

#include <string>

#include "rigidfem/profiles.hpp"
#include "rigidfem/transforms.hpp"

namespace rigidfem {

/// What a loop joint leaves free between frame A (on body a) and frame B (on body b), with the
/// frames coinciding at assembly:
///   Revolute: rotation about the common z axis;        Spherical: every rotation;
///   Universal: rotation about A's x and B's y axes;     Prismatic: translation along z;
///   Cylindrical: translation along and rotation about z; Fixed: nothing;
///   Planar: translation in the x–y plane and rotation about z;
///   Distance: everything but the distance |r_B − r_A| = l (constant, or l(t) for an actuator).
/// A kind is its name here and its row of the table of kinds in constraints.cpp (its constraint rows, what it leaves
/// free); the Python layer (rigidfem.loops, the analyses) reads the table through _core._loop_kind_table.
enum class LoopKind { Revolute, Spherical, Universal, Prismatic, Cylindrical, Fixed, Planar, Distance };
/// The number of kinds.
constexpr int loop_kind_count = 8;

/// One loop closure as the user describes it. Body −1 is the ground.
struct Loop {
  std::string name;
  LoopKind kind = LoopKind::Spherical;
  int body_a = -1, body_b = -1;
  Mat4 frame_a = Mat4::Identity();  ///< pose of frame A in body a's frame (Distance: only its origin counts)
  Mat4 frame_b = Mat4::Identity();  ///< pose of frame B in body b's frame
  double length = 0.0;              ///< Distance: l in m when `drive` is null
  ProfilePtr drive;                 ///< Distance: prescribed length l(t) (an actuator under position control)
  bool actuator = false;            ///< Distance: a linear actuator (Model.add_actuator), drawn as one
};

/// The number of constraint equations of a loop joint of that kind.
int loop_rows(LoopKind kind);
/// "revolute", ...; and back (std::invalid_argument naming `argument` for an unknown kind).
const char* loop_kind_name(LoopKind kind);
/// What a loop joint of that kind leaves free, in words (the site's table).
const char* loop_kind_doc(LoopKind kind);
LoopKind parse_loop_kind(const std::string& name, const std::string& argument);

}  // namespace rigidfem

/// A compiled system with some of its constants or profiles changed, without compiling its model again: what
/// a named parameter of the Python API (rigidfem/model/parameters.py) sets. The constants are those the equations of
/// motion are linear in — a body's pseudo-inertia H, a coordinate's laws' constants (its spring k, damper c and
/// applied force, a friction's forces), a force element's constants, a load's force and torque — so a parameter's
/// derivative of the residual
/// r = M q̈ − f is the difference of two such systems' residuals (sensitivities.hpp). The profiles — a
/// coordinate's drive, a force element's profile (a winch's l_u(t), a cylinder's F(t)), a load's scale and an
/// actuator's length — carry the coefficients of the motions (the residual is not linear in those).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "rigidfem/system.hpp"

namespace rigidfem {

/// New values of some constants of a System.
struct ConstantChanges {
  /// A constant of a joint coordinate's law (coordinate_laws.hpp), by the name its description gives it.
  struct CoordinateConstant {
    int body = -1, slot = 0;  ///< the coordinate: slot `slot` of body `body`'s joint
    int law = -1;             ///< −1: its spring-damping law; k ≥ 0: its further law k
    std::string name;         ///< "stiffness", "damping", "force", "breakaway", ...
    double value = 0.0;
  };
  struct BodyInertia {
    int body = -1;
    Mat4 H = Mat4::Zero();  ///< pseudo-inertia ∫ r rᵀ dm, body frame (kg, kg·m, kg·m²)
  };
  struct ElementConstant {
    int element = -1;
    std::string name;  ///< the law's constant ("stiffness", "damping", "force"; a rope's "EA", "damping")
    double value = 0.0;
  };
  struct ContactConstant {
    int contact = -1;
    std::string name;  ///< the contact law's constant ("stiffness", "mu_s", "mu_k")
    double value = 0.0;
  };
  struct LoadValues {
    int load = -1;
    Vec3 force = Vec3::Zero(), torque = Vec3::Zero();  ///< N, N·m
  };
  /// A new profile for what had one: "drive" (the coordinate at slot `index` of body `body`), "element", "load"
  /// or "loop" (number `index`).
  struct NewProfile {
    std::string what;
    int body = -1, index = -1;
    ProfilePtr profile;
  };
  std::vector<CoordinateConstant> coordinates;
  std::vector<BodyInertia> bodies;
  std::vector<ElementConstant> elements;
  std::vector<LoadValues> loads;
  std::vector<NewProfile> profiles;
  std::vector<ContactConstant> contacts;
};

/// A copy of sys with the changes applied (O(n): the tables are copied). std::invalid_argument naming the
/// change that does not fit the system (a body, coordinate, element or load it does not have, an unknown
/// constant, a pseudo-inertia without positive mass). Signs are not checked: the central differences of
/// sensitivities.hpp step a constant at zero to both sides.
std::shared_ptr<System> with_constants(const System& sys, const ConstantChanges& changes);

}  // namespace rigidfem

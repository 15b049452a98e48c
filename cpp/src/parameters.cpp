// System copies with changed constants (parameters.hpp).
#include "rigidfem/parameters.hpp"

#include <cmath>
#include <stdexcept>

#include "rigidfem/errors.hpp"

namespace rigidfem {

namespace {

// The coordinate (index in sys.coords) at slot `slot` of body `body`'s joint.
int coordinate_at(const System& sys, int body, int slot) {
  check_body(sys, body, "body");
  const int first = sys.coord_start[body], count = sys.coord_start[body + 1] - first;
  if (slot < 0 || slot >= count)
    bad("slot", "a coordinate of body '" + sys.body_names[body] + "' (0.." + std::to_string(count - 1) + ")",
        std::to_string(slot));
  return first + slot;
}

// H = [[½ tr(I_O) 1 − I_O, m c], [m cᵀ, m]] into the body's mass, centre of mass and inertia about it.
void set_inertia(System& s, int body, const Mat4& H) {
  check_body(s, body, "body");
  const double m = H(3, 3);
  if (!(m > 0.0 && H.allFinite()))
    bad("H", "a finite pseudo-inertia with a positive mass for body '" + s.body_names[body] + "'", "mass " + num(m));
  const Vec3 c = H.block<3, 1>(0, 3) / m;
  const Mat3 S = H.topLeftCorner<3, 3>();
  const Mat3 IO = S.trace() * Mat3::Identity() - S;
  s.H[body] = H;
  s.mass[body] = m;
  s.com[body] = c;
  s.inertia[body] = IO - m * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
}

}  // namespace

std::shared_ptr<System> with_constants(const System& sys, const ConstantChanges& changes) {
  auto copy = std::make_shared<System>(sys);
  System& s = *copy;
  for (const auto& c : changes.coordinates) {
    Coordinate& coordinate = s.coords[coordinate_at(s, c.body, c.slot)];
    if (c.law < 0) {
      coordinate.spring.set(constant_index(SpringDamping::description(), c.name), c.value);
      continue;
    }
    if (c.law >= static_cast<int>(coordinate.laws.size()))
      bad("law", "a law of coordinate '" + coordinate.name + "' (0.." + std::to_string(coordinate.laws.size()) + " - 1)",
          std::to_string(c.law));
    coordinate.laws[c.law] = coordinate.laws[c.law]->with_constant(c.name, c.value);
  }
  for (const auto& b : changes.bodies) set_inertia(s, b.body, b.H);
  for (const auto& c : changes.contacts) {
    if (c.contact < 0 || c.contact >= static_cast<int>(s.contacts.size()))
      bad("contact", "a contact of this system (0.." + std::to_string(s.contacts.size()) + " - 1)",
          std::to_string(c.contact));
    s.contacts[c.contact].law = s.contacts[c.contact].law->with_constant(c.name, c.value);
  }
  // a contact's restitution is bounded above (e <= 1) as well as below: its law judges the values it was given
  for (const auto& c : changes.contacts) {
    try {
      s.contacts[c.contact].law->validate();
    } catch (const std::invalid_argument& e) {
      bad("values", "values of contact '" + s.contacts[c.contact].name + "' its law accepts", e.what());
    }
  }
  for (const auto& e : changes.elements) {
    if (e.element < 0 || e.element >= static_cast<int>(s.elements.size()))
      bad("element", "a force element of this system (0.." + std::to_string(s.elements.size()) + " - 1)",
          std::to_string(e.element));
    s.elements[e.element].law = s.elements[e.element].law->with_constant(e.name, e.value);
  }
  for (const auto& L : changes.loads) {
    if (L.load < 0 || L.load >= static_cast<int>(s.loads.size()))
      bad("load", "a load of this system (0.." + std::to_string(s.loads.size()) + " - 1)", std::to_string(L.load));
    s.loads[L.load].force = L.force;
    s.loads[L.load].torque = L.torque;
  }
  for (const auto& p : changes.profiles) {
    if (!p.profile) bad("profile", "a profile", "None");
    if (p.what == "drive") {
      Coordinate& c = s.coords[coordinate_at(s, p.body, p.index)];
      if (!c.drive) bad("drive", "a prescribed coordinate", "'" + c.name + "', a free one");
      c.drive = p.profile;
    } else if (p.what == "element") {
      if (p.index < 0 || p.index >= static_cast<int>(s.elements.size())) bad("element", "an element", std::to_string(p.index));
      s.elements[p.index].law = s.elements[p.index].law->with_profile(p.profile);
    } else if (p.what == "load") {
      if (p.index < 0 || p.index >= static_cast<int>(s.loads.size()) || !s.loads[p.index].scale)
        bad("load", "a load scaled by a profile", std::to_string(p.index));
      s.loads[p.index].scale = p.profile;
    } else if (p.what == "loop") {
      if (p.index < 0 || p.index >= static_cast<int>(s.loops.size()) || !s.loops[p.index].drive)
        bad("loop", "an actuator (a distance loop with a length profile)", std::to_string(p.index));
      s.loops[p.index].drive = p.profile;
    } else if (p.what == "flow") {  // a link's free length L(t): the flow's, and its sdes' growth κ_k (L − L₀)
      if (p.index < 0 || p.index >= static_cast<int>(s.flows.size()))
        bad("flow", "a link of varying length", std::to_string(p.index));
      Flow& f = s.flows[p.index];
      f.length = p.profile;
      for (int k = 1; k <= f.elements; ++k)
        s.coords[coordinate_at(s, f.first + k, 0)].drive = growth_profile(f.length, f.spacing(k), f.length0);
    } else {
      bad("what", "'drive', 'element', 'load', 'loop' or 'flow'", "'" + p.what + "'");
    }
  }
  return copy;
}

}  // namespace rigidfem

"""Flexible links of time-varying free length L(t) (book ch. 7.2: the telescopic rapier).

``Model.add_beam(..., length=profile)`` builds a uniform beam of m sdes whose free length follows
the profile L(t) (m): its material slides out of the guide — the beam's frame, whose joint
(``joint=``, ``placement=``) carries the guide — at the speed v = L̇ (v < 0: back into it).

The design (a fixed number of rfes spread over the current length, no events, O(n) kept):

- the rfe frames sit at the normalised positions ξ_0 = 0 and ξ_k = (k − ½)/m; rfe k spans the
  fraction σ_k of L (½/m at the ends, 1/m between) and has the mass ρA σ_k L(t); the frames
  move apart through a prescribed "x" coordinate x_k(t) = κ_k (L(t) − L(0)) first in each sde
  joint (its driving force is the axial force that spreads the chain);
- the sdes' springs and dampers scale as 1/L: c = EI m / L(t) (and GJ, κGA likewise);
- a material point moves through the chain as ξ̇ = v (1 − ξ)/L, i.e. relative to the frame of its
  rfe k at u_k = v (1 − ξ_k) along the rfe's axis e_k, with the relative acceleration
  v̇ (1 − ξ_k) e_k, and it turns at each sde from e_{k−1} to e_k. d'Alembert's principle over
  the material particles adds to the tree's equations the loads −m_k (2 ω_k × u_k + v̇ (1 − ξ_k) e_k)
  at each rfe's centre of mass (Coriolis and relative acceleration) and −ρA v² (1 − ξ_k)² (e_k − e_{k−1})
  at each sde (the turn; at small deflection the concentrated transverse force ρA v² (1 − ξ)² q_k).

With v = 0 the link is the ordinary cantilever of length L. Both engines evaluate these terms;
the recursive engine's tangents include them exactly. ``Beam.tip_positions(result)`` and
``Beam.centerline(system, q, t)`` give the free end at its current place.
"""

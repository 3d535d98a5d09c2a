#pragma once
/// What the triaxial test measures beyond the stresses (host/engine/stress.hpp): the cross-sections and the membrane's
/// hoop stress with which labs correct the deviator from the platen force, the volume of the balls' own envelope,
/// balls that left the membrane, and the membrane as a surface for the snapshots.
#include <vector>

#include "host/io/io_hdf5.hpp"
#include "host/engine/micro.hpp"
#include "kernels/motion/membrane.hpp"

namespace dem {

class Simulation;

/// The specimen's cross-section as a lab takes it from its strains, for q = F / A (the right-cylinder correction of
/// ASTM D4767 and D7181; docs/running.md, "Which q"): A0 (1 - eps_v) / (1 - eps_a), with A0
/// the cross-section after consolidation and strains compression positive. With A0 = V0 / h0 it is V / h, and
/// F / A is then the volume-averaged axial stress of a barrelled specimen too.
Real right_cylinder_area(Real a0, Real eps_a, Real eps_v);

/// The mid-height cross-section of a specimen whose profile is a parabola with its ends held at the platens'
/// radius (the barrelling correction of Germaine & Ladd 1988 and Zhang & Garga 1997 in its drained form):
/// with k = (1 - eps_v) / (1 - eps_a), r_mid / r0 = (sqrt(30 k - 5) - 1) / 4 and A = A0 (r_mid / r0)^2.
/// q = F / A is then the deviator of the widest, weakest section.
Real parabolic_mid_area(Real a0, Real eps_a, Real eps_v);

/// The lateral stress a thin elastic membrane adds to the cell pressure by its hoop tension (Pa), as a lab
/// estimates it: 2 E t eps_theta / D0, with eps_theta = sqrt(A / A0) - 1 the hoop strain of the right
/// cylinder and D0 its diameter after consolidation. Zero where the membrane would be compressed: it wrinkles.
Real membrane_hoop_stress(Real young, Real thickness, Real d0, Real eps_a, Real eps_v);

/// The membrane as a triangle surface for the snapshots (ParaView shows it with the balls).
io::SurfaceSnapshot membrane_surface(const Membrane& m);

/// Volume of the balls' envelope (m^3), measured without the membrane: the specimen between the bottom
/// platen (z = 0) and `top` cut into `slabs` slabs, each slab's cross-section the convex hull of its balls
/// (centres within the slab, grown by `mean_radius`). It bounds the granular body as a wrapping membrane
/// would, except for the dimples a soft membrane makes between the outer balls. `centres`: the balls' in gid order.
Real envelope_volume(const std::vector<Vec3>& centres, Real top, Real mean_radius, int slabs);
Real envelope_volume(Simulation& sim, Real top, Real mean_radius, int slabs);

/// Balls whose centre lies outside the membrane tube or beyond the platens (z < 0 or z > top). Inside the
/// tube a ray from the centre straight away from the axis crosses the membrane an odd number of times; this
/// holds wherever the membrane bulges, unlike a comparison with a mean ring radius.
int count_escaped(Simulation& sim, const Membrane& m, Real top);

}  // namespace dem

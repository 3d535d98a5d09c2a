#pragma once
/// What the triaxial test measures beyond the platen forces: the lateral stress the balls receive through
/// the membrane, the volume of the balls' own envelope, balls that left the membrane, and the membrane as
/// a surface for the snapshots.
#include <vector>

#include "host/io_hdf5.hpp"
#include "kernels/membrane.hpp"

namespace dem {

class Simulation;

/// The membrane as a triangle surface for the snapshots (ParaView shows it with the balls).
io::SurfaceSnapshot membrane_surface(const Membrane& m);

/// Lateral stress the balls exert on the membrane (Pa): the outward normal component of the ball-facet forces
/// over the area of the facets clear of the end rings. It differs from the cell pressure by what the
/// membrane itself carries (hoop and axial tension of a deforming membrane, inertia). The end bands are left
/// out: the balls cannot fill the corner between platen and membrane, so there the tied rings and the
/// platen edge carry part of the pressure, as a lab's platens do.
/// `wall_forces`: Simulation::wall_forces() of this step.
Real lateral_stress(Simulation& sim, const Membrane& m, const std::vector<Vec3>& wall_forces);

/// Volume of the balls' envelope (m^3), measured without the membrane: the specimen between the bottom
/// platen (z = 0) and `top` cut into `slabs` slabs, each slab's cross-section the convex hull of its balls
/// (centres within the slab, grown by `mean_radius`). It bounds the granular body as a wrapping membrane
/// would, except for the dimples a soft membrane makes between the outer balls.
Real envelope_volume(Simulation& sim, Real top, Real mean_radius, int slabs);

/// Balls whose centre lies outside the membrane tube or beyond the platens (z < 0 or z > top). Inside the
/// tube a ray from the centre straight away from the axis crosses the membrane an odd number of times; this
/// holds wherever the membrane bulges, unlike a comparison with a mean ring radius.
int count_escaped(Simulation& sim, const Membrane& m, Real top);

}  // namespace dem

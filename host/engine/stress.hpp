#pragma once
/// Every stress the program reports, one function each, and every contact term through the one Love-Weber formula
/// (kernels/contact/contact_sums.hpp: love_weber_term). Pa, compression positive, z the specimen's axis; the
/// measures and their corrections are in docs/running.md ("Which q") and docs/physics.md.
///
/// Where each is read:
/// - the periodic cell's servo and records: Simulation::contact_stress_diagonal (CellBatch::contact_stress_diagonals
///   for a batch), the ball-ball contacts' sums on the device; a walled cell's: walled_cell_stress
///   (host/triax/cell_boundary.hpp: cell_stress takes one or the other);
/// - the membrane test's records: its platens' force (host/triax/triaxial_cell.hpp: platen_stresses), the membrane's
///   lateral_stress, and specimen_stress, on the device once a record;
/// - the micromechanics of a region (the specimen, its central cube): love_weber and boundary_stress of a ContactSet.
#include <array>
#include <vector>

#include "host/engine/micro.hpp"
#include "host/engine/state_copy.hpp"
#include "kernels/motion/membrane.hpp"

namespace dem {

class Simulation;

/// Axial deviator t_zz - (t_xx + t_yy)/2 of a tensor: q of a stress.
Real axial_deviator(const Tensor& t);
/// The same of the normal stresses (xx, yy, zz) of a cell.
Real axial_deviator(const std::array<Real, 3>& s);
/// Mean of the diagonal, tr / 3: p of a stress.
Real mean_stress(const Tensor& t);
/// The same of the normal stresses (xx, yy, zz) of a cell.
Real mean_stress(const std::array<Real, 3>& s);
/// p of a triaxial test from its lateral stress sigma3 and deviator q (Pa), as labs report it: sigma3 + q / 3.
Real triaxial_mean_stress(Real sigma3, Real q);
/// Triaxial stress ratio q/p of a stress tensor (p = tr/3); zero when p <= 0.
Real stress_ratio(const Tensor& s);

/// t += (1/V) f (x) l of contact c (f the force ball a exerts on the other side, l its branch): a region's sums.
void add_love_weber(Tensor& t, const ContactRecord& c, Real volume);
/// Love-Weber stress (1/V) sum f (x) l over the contacts of a region in volume V: with boundary contacts included it
/// is the region's mean stress.
Tensor love_weber(const ContactSet& s, Real volume, bool include_boundary);
/// Boundary stress (1/V) sum f (x) x_c over the boundary contacts (platens, membrane): each contact point with the
/// force the ball exerts on the boundary, about the origin: the stress a lab would read off its boundaries with the
/// enclosed volume V. By the average-stress theorem (Newton's law for each ball, summed over the balls: exact at
/// every step) love_weber(s, V, true) exceeds it by (1/V) sum_p F_p (x) x_p, F_p each ball's net contact force:
/// the two agree as far as the balls are at rest.
Tensor boundary_stress(const ContactSet& s, Real volume);

/// A specimen's stresses over its volume V from every contact, summed on the device per particle and then in gid
/// order (one launch, one copy): their bits do not depend on the lists' rebuilds.
struct SpecimenStress {
  Tensor love_weber;  ///< every contact's term, ball-ball and ball-boundary: the specimen's mean stress
  Tensor boundary;    ///< the boundaries' x_c (x) f
  Tensor net_force;   ///< (1/V) sum_p F_p (x) x_p, the balls' net contact forces of the last step: love_weber - boundary
};
SpecimenStress specimen_stress(const Simulation& sim, Real volume);

/// Lateral stress the balls exert on the membrane: the outward normal component of the ball-facet forces over the
/// area of the facets clear of the end rings. It differs from the cell pressure by what the membrane itself carries
/// (hoop and axial tension of a deforming membrane, inertia). The end bands are left out: the balls cannot fill the
/// corner between platen and membrane, so there the tied rings and the platen edge carry part of the pressure, as a
/// lab's platens do. `state`: copied at this step, its facets the membrane's; `wall_forces`: Simulation::wall_forces()
/// of this step (analytic walls, then the facets), the facets' from `first_facet` (Simulation::num_walls()).
Real lateral_stress(const ContactCopy& state, int first_facet, const std::vector<Vec3>& wall_forces);

/// A cell between six walls (wall 2d the lower, 2d + 1 the upper along axis d): sigma_dd, the mean of what the balls
/// push the two walls apart with, over the face between the other two lengths `l`.
std::array<Real, 3> walled_cell_stress(const std::vector<Vec3>& wall_forces, const std::array<Real, 3>& l);

}  // namespace dem

#pragma once
/// What a Simulation (one cell) and a CellBatch (a cell among many) do alike for a cell, written once: the sums a cell
/// servo on the device reads before its step, and the unbalanced-force ratio. Each engine passes how it sums a cell's
/// contacts, `reduce(label, terms, root)`: OwnerSums of `terms` over the cell's particles to device memory at `root`
/// (a Simulation: its one tree over its gids; a batch: its segmented tree, a row per specimen). The same terms in the
/// same trees: a specimen's bits in a batch are its own Simulation's.
#include "kernels/contact/contact_sums.hpp"
#include "kernels/motion/cell_servo.hpp"

namespace dem {

/// The sums a cell servo on the device reads before its step (CellServoSums, from `sums`): the stiffness's where
/// `fresh` (every stiffness_every calls), the contacts' Love-Weber diagonal every step.
template <class Reduce, class Images>
void cell_servo_sums(const Reduce& reduce, const ConstVec3View& x, const ConstScalarView& r, const Images& images,
                     bool fresh, Real* sums) {
  if (fresh)
    reduce("dem::cell::servo_stiffness", StiffnessTerms<Images>{x, r, images}, sums + CellServoSums::kStiffnessSums);
  reduce("dem::cell::servo_stress", LoveWeberTerms<3, Images>{x, images}, sums + CellServoSums::kStressSums);
}

/// The unbalanced-force ratio of a cell's `balls` balls: their mean unbalanced force (`unbalanced`, the sum) over the
/// mean force of the touching contacts (`force`, |f| summed over `touching` of them); 1 where none touch.
inline Real unbalanced_ratio(Real unbalanced, long balls, Real force, Real touching) {
  if (touching == 0) return 1;
  return (unbalanced / static_cast<Real>(balls)) / (force / touching);
}

}  // namespace dem

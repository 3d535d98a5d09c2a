#pragma once
/// Compression tests of a cell, loaded in increments as a lab loads an oedometer or an isotropic cell: after the
/// cell's isotropic consolidation to [periodic] sigma3 (the seating stress), each increment holds its target stress
/// until the cell is at rest (the consolidation's tolerances), and then a row is recorded.
///   oedometer: the lateral axes (x, y) held at their lengths, the axial (z) stress servoed to the target:
///              one-dimensional compression, K0 = sigma_h / sigma_v on the record;
///   isotropic: every axis servoed to the target, the mean stress p: void ratio against p.
/// The cell is periodic or between walls (host/triax/cell_control.hpp); stresses are measured as the triaxial test
/// measures them (host/triax/periodic_triaxial.hpp), compression positive, and strains count from the seating state.
#include <string>
#include <vector>

#include "host/data/compression_data.hpp"
#include "host/engine/stage_loop.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/triax/periodic_triaxial.hpp"

namespace dem {

/// One row: the cell at rest at an increment's target (SI; the first row at the seating stress).
struct CompressionRecord {
  long step = 0;
  Real target = 0;                ///< Pa: the increment's axial stress (oedometer) or mean stress (isotropic)
  Real eps_a = 0, eps_v = 0;      ///< from the seating state, compression positive
  Real sigma_v = 0, sigma_h = 0;  ///< Pa: zz, and the mean of xx and yy
  Real p = 0, q = 0;              ///< Pa
  Real k0 = 0;                    ///< sigma_h / sigma_v
  Real void_ratio = 0;
  Real coordination = 0;          ///< 2 x touching ball-ball contacts / balls
  Real unbalanced = 0;
};

struct CompressionResult {
  CompressionPath path = CompressionPath::oedometer;
  std::vector<CompressionRecord> series;
  std::vector<StageTiming> stages;  ///< the consolidation, then one per increment
};

/// The test on `sim` (a cell as run_periodic_triaxial takes it): consolidation to prm.sigma3, then the increments
/// `targets` (Pa, loading and unloading in the order given). With `out`, series.csv/.h5 get a row per increment.
/// Throws as consolidate_isotropic does, naming the increment that did not converge.
CompressionResult run_compression_test(Simulation& sim, const PeriodicTriaxialParams& prm, CompressionPath path,
                                       const std::vector<Real>& targets, io::Output* out = nullptr);

/// A test's record as compression data (host/data/compression_data.hpp): each increment's target and strain (axial
/// for the oedometer, volumetric for the isotropic path) and the oedometer's K0; the seating row is the origin.
CompressionTest compression_data_of(const CompressionResult& r, const std::string& material, Real sigma3);

/// The series' columns and a row in them (kPa, %).
const std::vector<std::string>& compression_columns();
std::vector<double> compression_row(const CompressionRecord& r);

}  // namespace dem

#pragma once
/// What the cell test's stages read of their cell and set on it (host/triax/periodic_triaxial.hpp): the cell of a
/// Simulation, periodic or between walls (host/triax/cell_boundary.hpp, where the quantities are defined), or a
/// specimen of a batch of periodic cells (host/engine/cell_batch.hpp). The stages are written once against this.
#include <array>
#include <memory>

#include "kernels/core/vec3.hpp"
#include "kernels/motion/cell_servo.hpp"

namespace dem {

class Simulation;
class CellBatch;

class CellControl {
 public:
  virtual ~CellControl() = default;
  virtual std::array<Real, 3> lengths() const = 0;  ///< L_d (m)
  /// L_d (m) of axis d alone: a cell steered on the device knows an axis its servo does not steer without a read.
  virtual Real length(int d) const { return lengths()[static_cast<std::size_t>(d)]; }
  virtual Real volume() const = 0;                   ///< m^3
  virtual std::array<Real, 3> stress() = 0;          ///< sigma_dd (Pa, compression positive)
  virtual std::array<Real, 3> stiffness() = 0;       ///< the servo's K_dd (Pa)
  virtual void set_rates(const Vec3& rate) = 0;      ///< strain rates of the next steps (1/s, extension positive)
  /// Hands the servo `spec` to the device for the steps until set_rates, where the cell can take it (a periodic cell:
  /// Simulation::set_cell_servo, CellBatch::set_cell_servo); false where the host servos it before each step (walls).
  virtual bool servo_on_device(const CellServoSpec&) { return false; }
  virtual Vec3 rates() const = 0;
  virtual Real dt() const = 0;                        ///< s
  virtual long step_count() const = 0;
  virtual Real time() const = 0;                      ///< s
  virtual long touching() = 0;                        ///< touching ball-ball contacts
  virtual Real unbalanced_ratio() = 0;                ///< Simulation::unbalanced_ratio's
  virtual Real kinetic() = 0;                         ///< J, of the last measured step
  virtual int balls() const = 0;
};

/// The cell of `sim`, or specimen s of `batch`; each must outlive what it gives.
std::unique_ptr<CellControl> cell_of(Simulation& sim);
std::unique_ptr<CellControl> cell_of(CellBatch& batch, int s);

}  // namespace dem

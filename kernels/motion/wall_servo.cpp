#include "kernels/motion/wall_servo.hpp"

namespace dem {

void wall_servo_velocity(const WallServoSpec& spec, const WallLoadView& loads, bool no_contacts,
                         const Vec3View& wall_velocity, const Vec3View& node_velocity, Real dt, Real* speed) {
  const int tied = static_cast<int>(spec.tied.extent(0));
  Kokkos::parallel_for("dem::wall_servo::velocity", RangePolicy(0, tied > 0 ? tied : 1), KOKKOS_LAMBDA(const int k) {
    // Every item works the velocity out alike (a few operations), and the first alone writes the wall's.
    const WallLoad none;
    const WallLoad& load = no_contacts ? none : loads(spec.wall);
    const Real sigma = -spec.sign * load.force[spec.axis] / spec.servo.area;
    const Real along = spec.sign * spec.servo.speed(sigma, load.touching * spec.kn, dt);
    Real v[3] = {0, 0, 0};
    v[spec.axis] = along;
    const Vec3 vel(v[0], v[1], v[2]);
    if (k < tied) store(node_velocity, spec.tied(k), vel);
    if (k == 0) {
      store(wall_velocity, spec.wall, vel);
      *speed = norm(vel);
    }
  });
}

}  // namespace dem

// The boundaries' control from outside the step: the cell's rates and the walls' velocities and points set by the
// host, and the servos on the device (Simulation::set_cell_servo, set_wall_servo): their hand-over, their launches
// before a step, and the host's reads of what the device changed.
#include <stdexcept>
#include <string>

#include "host/engine/cell_services.hpp"
#include "host/engine/simulation.hpp"

namespace dem {

void Simulation::set_strain_rate(const Vec3& rate) {
  read_cell();
  servo_on_ = false;
  Domain& dom = prm_.domain;
  if (dom.strain_rate[0] == rate.x && dom.strain_rate[1] == rate.y && dom.strain_rate[2] == rate.z) return;
  dom.strain_rate[0] = rate.x;
  dom.strain_rate[1] = rate.y;
  dom.strain_rate[2] = rate.z;
  upload_cell();  // a constant rate: no copy
}

bool Simulation::store_wall_velocity(int w, const Vec3& v) {
  const Vec3 now = load(hwall_vel_, w);
  if (v.x == now.x && v.y == now.y && v.z == now.z) return false;
  store(hwall_vel_, w, v);
  return true;
}

void Simulation::set_wall_velocity(int w, const Vec3& v) {
  read_walls();
  if (w == wall_servo_.wall) wall_servo_on_ = false;
  if (store_wall_velocity(w, v)) Kokkos::deep_copy(walls_.velocity, hwall_vel_);  // a constant speed: no copy
}

void Simulation::set_wall_velocities(const std::vector<Vec3>& v) {
  if (static_cast<int>(v.size()) != walls_.n)
    throw std::invalid_argument("set_wall_velocities: " + std::to_string(v.size()) + " velocities for " +
                                std::to_string(walls_.n) + " walls");
  read_walls();
  wall_servo_on_ = false;
  bool changed = false;
  for (int w = 0; w < walls_.n; ++w) changed = store_wall_velocity(w, v[static_cast<std::size_t>(w)]) || changed;
  if (changed) Kokkos::deep_copy(walls_.velocity, hwall_vel_);
}

Vec3 Simulation::wall_velocity(int w) const {
  read_walls();
  return load(hwall_vel_, w);
}

Vec3 Simulation::wall_point(int w) const {
  read_walls();
  return load(hwall_point_, w);
}

void Simulation::set_wall_point(int w, const Vec3& p) {
  read_walls();
  read_rows();  // the steps before add to wall_disp_ first, as they happened first
  const Real moved = norm(p - load(hwall_point_, w));
  store(hwall_point_, w, p);
  Kokkos::deep_copy(walls_.point, hwall_point_);
  wall_disp_ += moved;
}

SpecimenTable Simulation::specimen() const {
  SpecimenTable one;
  one.one.integ = prm_.integ;
  one.cell = cell_;
  return one;
}

void Simulation::upload_cell() {
  Kokkos::deep_copy(cell_, Kokkos::View<Domain, HostSpace, Kokkos::MemoryUnmanaged>(&prm_.domain));
}

void Simulation::read_cell() const {
  if (!cell_stale_) return;
  Kokkos::deep_copy(Kokkos::View<Domain, HostSpace, Kokkos::MemoryUnmanaged>(&prm_.domain), cell_);
  cell_stale_ = false;
}

Real Simulation::axis_length(int d) const {
  if (servo_on_ && servo_.servo[d]) read_cell();
  return prm_.domain.length(d);
}

void Simulation::set_cell_servo(const CellServoSpec& spec) {
  const Domain& dom = domain();
  if (!(dom.periodic[0] && dom.periodic[1] && dom.periodic[2]))
    throw std::invalid_argument("set_cell_servo: the cell must be periodic along x, y and z");
  servo_ = spec;
  servo_on_ = true;
  servo_calls_ = 0;
  take_fixed_rates(prm_.domain, spec);
}

void Simulation::servo_step() {
  const bool fresh = servo_calls_++ % servo_.stiffness_every == 0;
  // Device memory: the host passes it on, never reads it.
  cell_servo_sums([&](const char* label, const auto& terms, Real* root) { owner_sums_to<3>(label, terms, root); },
                  p_.x, p_.radius, CellImage{cell_}, fresh, servo_sums_.data());
  cell_servo_rates(cell_, servo_, servo_sums_, fresh, prm_.integ.dt);
  cell_stale_ = true;
}

void Simulation::read_walls() const {
  if (!walls_stale_) return;
  Kokkos::deep_copy(hwall_point_, walls_.point);
  Kokkos::deep_copy(hwall_vel_, walls_.velocity);
  walls_stale_ = false;
}

void Simulation::set_wall_servo(const WallServoSpec& spec) {
  if (spec.wall < 0 || spec.wall >= walls_.n || spec.axis < 0 || spec.axis > 2)
    throw std::invalid_argument("set_wall_servo: wall " + std::to_string(spec.wall) + " or axis " +
                                std::to_string(spec.axis) + " out of range");
  if (static_cast<int>(wall_load_.extent(0)) < walls_.n)
    wall_load_ = WallLoadView("dem::sim::wall_loads", walls_.n);  // here, not in a step
  wall_servo_ = spec;
  wall_servo_on_ = true;
}

}  // namespace dem

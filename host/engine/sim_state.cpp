#include <cmath>
#include <stdexcept>
#include <string>

#include "host/engine/simulation.hpp"

namespace dem {

namespace {

template <class View>
std::vector<double> vec3_out(const View& v, int n) {
  const auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  std::vector<double> out(3 * std::size_t(n));
  for (int k = 0; k < n; ++k)
    for (int d = 0; d < 3; ++d) out[3 * std::size_t(k) + d] = h(k, d);
  return out;
}

template <class T, class View>
std::vector<T> scalar_out(const View& v, int n) {
  const auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
  std::vector<T> out(n);
  for (int k = 0; k < n; ++k) out[k] = h(k);
  return out;
}

/// Fills the first n rows of an existing View of at least n rows.
template <class View>
void vec3_in(const View& v, const std::vector<double>& src, int n) {
  auto h = Kokkos::create_mirror_view(v);
  for (int k = 0; k < n; ++k)
    for (int d = 0; d < 3; ++d) h(k, d) = src[3 * std::size_t(k) + d];
  Kokkos::deep_copy(v, h);
}

template <class View, class T>
void scalar_in(const View& v, const std::vector<T>& src, int n) {
  auto h = Kokkos::create_mirror_view(v);
  for (int k = 0; k < n; ++k) h(k) = src[k];
  Kokkos::deep_copy(v, h);
}

SavedContacts history_out(const ContactList& c) {
  SavedContacts h;
  h.key = scalar_out<std::uint64_t>(c.key, c.n);
  h.i = scalar_out<int>(c.i, c.n);
  h.j = scalar_out<int>(c.j, c.n);
  h.fs = vec3_out(c.fs, c.n);
  h.mr = vec3_out(c.mr, c.n);
  for (int s = 0; s < kHistorySlots; ++s) h.slot[s] = scalar_out<double>(c.slot[s], c.n);
  h.flags = scalar_out<std::uint8_t>(c.flags, c.n);
  h.fc = vec3_out(c.fc, c.n);
  h.mt = vec3_out(c.mt, c.n);
  h.fn = scalar_out<double>(c.fn, c.n);
  return h;
}

ContactList history_in(const SavedContacts& h, const char* which) {
  const std::size_t n = h.key.size();
  if (h.i.size() != n || h.j.size() != n || h.fs.size() != 3 * n || h.mr.size() != 3 * n ||
      h.flags.size() != n || h.fc.size() != 3 * n || h.mt.size() != 3 * n || h.fn.size() != n)
    throw std::runtime_error(std::string("state: the ") + which + " contact list has arrays of unequal length");
  for (const auto& v : h.slot)
    if (v.size() != n) throw std::runtime_error(std::string("state: the ") + which + " contact list has arrays of unequal length");
  ContactList c(static_cast<int>(n));
  scalar_in(c.key, h.key, c.n);
  scalar_in(c.i, h.i, c.n);
  scalar_in(c.j, h.j, c.n);
  vec3_in(c.fs, h.fs, c.n);
  vec3_in(c.mr, h.mr, c.n);
  for (int s = 0; s < kHistorySlots; ++s) scalar_in(c.slot[s], h.slot[s], c.n);
  scalar_in(c.flags, h.flags, c.n);
  vec3_in(c.fc, h.fc, c.n);
  vec3_in(c.mt, h.mt, c.n);
  scalar_in(c.fn, h.fn, c.n);
  return c;
}

void check_count(const char* what, std::size_t got, std::size_t want) {
  if (got != want)
    throw std::runtime_error(std::string("state: ") + what + ": " + std::to_string(got) + " in the saved state, " +
                             std::to_string(want) + " in this simulation (the config describes another system)");
}

[[noreturn]] void refuse(const std::string& what, std::size_t row, const std::string& allowed) {
  throw std::runtime_error("state: " + what + ", row " + std::to_string(row) + ": " + allowed);
}

/// Values stored `columns` to a row (3 for vectors, interleaved); the error names the row.
void check_finite(const std::string& what, const std::vector<double>& v, std::size_t columns = 1,
                  bool positive = false) {
  for (std::size_t k = 0; k < v.size(); ++k)
    if (!std::isfinite(v[k]) || (positive && !(v[k] > 0)))
      refuse(what, k / columns, positive ? "not a finite positive number" : "not a finite number");
}

/// A saved contact list against the particles it indexes: keys strictly increasing (the lists are sorted, and
/// lookups rely on it), each key naming its particles (by gid) or its wall object, and the local indices i, j
/// those of the key, as the remap after a rebuild sets them.
void check_contacts(const SavedContacts& h, const char* which, bool ball_ball, const std::vector<int>& local_of_gid,
                    std::size_t objects) {
  const std::string list = std::string("the ") + which + " contacts";
  auto local = [&](std::uint32_t gid, std::size_t k) {
    if (gid >= local_of_gid.size()) refuse(list + ": key", k, "names particle " + std::to_string(gid) +
                                                                  " (allowed: below " + std::to_string(local_of_gid.size()) + ")");
    return local_of_gid[gid];
  };
  for (std::size_t k = 0; k < h.key.size(); ++k) {
    if (k > 0 && h.key[k] <= h.key[k - 1]) refuse(list + ": key", k, "not above the previous key (keys are sorted)");
    const std::uint32_t hi = key_hi(h.key[k]), lo = key_lo(h.key[k]);
    int want_i, want_j;
    if (ball_ball) {
      if (hi >= lo) refuse(list + ": key", k, "its first particle must have the lower id");
      want_i = local(hi, k);
      want_j = local(lo, k);
    } else {
      if (hi >= objects)
        refuse(list + ": key", k, "names object " + std::to_string(hi) + " (allowed: below " + std::to_string(objects) + ")");
      want_i = local(lo, k);
      want_j = static_cast<int>(hi);
    }
    if (h.i[k] != want_i || h.j[k] != want_j)
      refuse(list + ": i, j", k, "(" + std::to_string(h.i[k]) + ", " + std::to_string(h.j[k]) + ") where the key gives (" +
                                     std::to_string(want_i) + ", " + std::to_string(want_j) + ")");
  }
  for (const auto* v : {&h.fs, &h.mr, &h.fc, &h.mt}) check_finite(list + " history", *v, 3);
  check_finite(list + " history", h.fn);
  for (int s = 0; s < kHistorySlots; ++s) check_finite(list + " history " + kHistorySlotNames[s], h.slot[s]);
}

}  // namespace

void check_state(const SimState& s, std::size_t walls, std::size_t facets, int materials) {
  const std::size_t n = s.radius.size();
  if (s.step < 0) refuse("step", 0, std::to_string(s.step) + " (allowed: 0 or more)");
  if (!std::isfinite(s.time) || s.time < 0) refuse("time", 0, "not a finite time of 0 or more");
  if (!std::isfinite(s.dt) || !(s.dt > 0)) refuse("dt", 0, "not a finite positive time step");
  for (int d = 0; d < 3; ++d)
    if (!std::isfinite(s.domain.lo[d]) || !std::isfinite(s.domain.hi[d]) || !std::isfinite(s.domain.strain_rate[d]) ||
        (s.domain.periodic[d] && !(s.domain.hi[d] > s.domain.lo[d])))
      refuse("domain", static_cast<std::size_t>(d), "bounds or strain rate not finite, or a periodic axis of no length");
  // Counts first: everything below indexes these arrays by particle and by contact row.
  const auto count = [](const char* what, std::size_t got, std::size_t want) {
    if (got != want)
      throw std::runtime_error(std::string("state: ") + what + ": " + std::to_string(got) + " values where " +
                               std::to_string(want) + " belong");
  };
  for (const auto* v : {&s.x, &s.v, &s.w, &s.f, &s.m, &s.x_ref}) count("a particle vector", v->size(), 3 * n);
  for (std::size_t size : {s.mass.size(), s.inertia.size(), s.gid.size(), s.specimen.size(), s.material.size()})
    count("a particle value", size, n);
  for (const SavedContacts* c : {&s.balls, &s.walls}) {
    count("a contact list's i", c->i.size(), c->key.size());
    count("a contact list's j", c->j.size(), c->key.size());
  }
  for (const auto* v : {&s.x, &s.v, &s.w, &s.f, &s.m, &s.x_ref}) check_finite("a particle vector", *v, 3);
  check_finite("radius", s.radius, 1, true);
  check_finite("mass", s.mass, 1, true);
  check_finite("inertia", s.inertia, 1, true);
  std::vector<int> local_of_gid(n, -1);
  for (std::size_t k = 0; k < s.gid.size(); ++k) {
    if (s.gid[k] >= n) refuse("gid", k, std::to_string(s.gid[k]) + " (allowed: 0 to " + std::to_string(n - 1) + ")");
    if (local_of_gid[s.gid[k]] >= 0) refuse("gid", k, std::to_string(s.gid[k]) + " given twice (ids are unique)");
    local_of_gid[s.gid[k]] = static_cast<int>(k);
  }
  for (std::size_t k = 0; k < s.material.size(); ++k)
    if (s.material[k] < 0 || s.material[k] >= materials)
      refuse("material", k, std::to_string(s.material[k]) + " (allowed: 0 to " + std::to_string(materials - 1) + ")");
  for (std::size_t k = 0; k < s.specimen.size(); ++k)
    if (s.specimen[k] < 0) refuse("specimen", k, std::to_string(s.specimen[k]) + " (allowed: 0 or more)");
  check_contacts(s.balls, "ball-ball", true, local_of_gid, 0);
  check_contacts(s.walls, "ball-wall", false, local_of_gid, walls + facets);
  for (const auto* v : {&s.wall_point, &s.wall_velocity, &s.node_x, &s.node_v}) check_finite("a wall or mesh node", *v, 3);
  if (!std::isfinite(s.cell_pressure) || !std::isfinite(s.wall_disp))
    refuse("cell pressure or wall travel", 0, "not a finite number");
  for (double v : {s.stats.unbalanced, s.stats.kinetic, s.stats.max_disp2, s.stats.max_move2})
    if (!std::isfinite(v)) refuse("step statistics", 0, "not a finite number");
}

SimState Simulation::state() const {
  read_rows();  // the statistics and the boundaries' travel as of the last step
  SimState s;
  s.step = step_;
  s.time = time_;
  s.dt = prm_.integ.dt;
  s.domain = domain();
  const int n = p_.n;
  s.x = vec3_out(p_.x, n);
  s.v = vec3_out(p_.v, n);
  s.w = vec3_out(p_.w, n);
  const Particles& forces = particles_with_forces();
  s.f = vec3_out(forces.f, n);
  s.m = vec3_out(forces.m, n);
  s.x_ref = vec3_out(p_.x_ref, n);
  s.radius = scalar_out<double>(p_.radius, n);
  s.mass = scalar_out<double>(p_.mass, n);
  s.inertia = scalar_out<double>(p_.inertia, n);
  s.gid = scalar_out<std::uint32_t>(p_.gid, n);
  s.specimen = scalar_out<int>(p_.specimen, n);
  s.material = scalar_out<int>(p_.material, n);
  s.balls = history_out(balls_);
  s.walls = history_out(wall_c_);
  read_walls();
  s.wall_point = vec3_out(hwall_point_, walls_.n);
  s.wall_velocity = vec3_out(hwall_vel_, walls_.n);
  s.node_x = vec3_out(mesh_.node_x, mesh_.nnode);
  s.node_v = vec3_out(mesh_.node_v, mesh_.nnode);
  s.cell_pressure = cell_pressure_;
  s.wall_disp = wall_disp_;
  s.stats = stats_;
  s.fresh = fresh_;
  return s;
}

void Simulation::restore(const SimState& s) {
  const std::size_t n = p_.n;
  check_count("balls", s.radius.size(), n);
  for (const auto* a : {&s.x, &s.v, &s.w, &s.f, &s.m, &s.x_ref}) check_count("ball vectors / 3", a->size() / 3, n);
  for (std::size_t size : {s.mass.size(), s.inertia.size(), s.gid.size(), s.specimen.size(), s.material.size()})
    check_count("ball values", size, n);
  check_count("walls", s.wall_point.size() / 3, walls_.n);
  check_count("wall velocities", s.wall_velocity.size() / 3, walls_.n);
  check_count("mesh nodes", s.node_x.size() / 3, mesh_.nnode);
  check_count("mesh node velocities", s.node_v.size() / 3, mesh_.nnode);
  check_state(s, static_cast<std::size_t>(walls_.n), static_cast<std::size_t>(mesh_.ntri),
              static_cast<int>(params_.extent(0)));
  step_ = s.step;
  time_ = s.time;
  prm_.integ.dt = s.dt;
  prm_.domain = s.domain;
  servo_on_ = false;
  cell_stale_ = false;
  upload_cell();
  vec3_in(p_.x, s.x, p_.n);
  vec3_in(p_.v, s.v, p_.n);
  vec3_in(p_.w, s.w, p_.n);
  vec3_in(p_.f, s.f, p_.n);
  vec3_in(p_.m, s.m, p_.n);
  forces_current_ = true;
  vec3_in(p_.x_ref, s.x_ref, p_.n);
  scalar_in(p_.radius, s.radius, p_.n);
  scalar_in(p_.mass, s.mass, p_.n);
  scalar_in(p_.inertia, s.inertia, p_.n);
  scalar_in(p_.gid, s.gid, p_.n);
  scalar_in(p_.specimen, s.specimen, p_.n);
  scalar_in(p_.material, s.material, p_.n);
  balls_ = history_in(s.balls, "ball-ball");
  wall_c_ = history_in(s.walls, "ball-wall");
  wall_servo_on_ = false;
  walls_stale_ = false;
  vec3_in(hwall_point_, s.wall_point, walls_.n);
  vec3_in(hwall_vel_, s.wall_velocity, walls_.n);
  Kokkos::deep_copy(walls_.point, hwall_point_);
  Kokkos::deep_copy(walls_.velocity, hwall_vel_);
  vec3_in(mesh_.node_x, s.node_x, mesh_.nnode);
  vec3_in(mesh_.node_v, s.node_v, mesh_.nnode);
  cell_pressure_ = s.cell_pressure;
  wall_disp_ = s.wall_disp;
  stats_ = s.stats;
  fresh_ = s.fresh;
  if (!fresh_) {
    integ_.renew(p_);
    index_contacts();
  }
  // Every step of the state has been read (state() reads them first). How fast the balls went is not stored: the
  // rows are read every step until the first read gives it.
  read_to_ = step_;
  step_bound_ = 0;
  node_bound_ = 0;
  unread_travel_ = 0;
}

}  // namespace dem

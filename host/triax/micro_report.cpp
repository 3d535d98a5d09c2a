#include "host/triax/micro_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <type_traits>

#include "host/engine/stress.hpp"
#include "host/io/io_hdf5.hpp"

namespace dem {

MicroRow micro_row(const ContactSet& s, Real volume) {
  MicroRow r;
  r.z = coordination(s);
  r.net = networks(s, volume);
  r.stress = love_weber(s, volume, true);
  r.all = anisotropy(s, Network::kAll, r.stress);
  r.strong = anisotropy(s, Network::kStrong, r.stress);
  r.weak = anisotropy(s, Network::kWeak, r.stress);
  r.q_over_p = stress_ratio(r.stress);
  r.q_over_p_sff = sff_stress_ratio(r.all);
  return r;
}

std::vector<std::string> micro_columns(const std::string& prefix) {
  std::vector<std::string> c = {"Z", "Z_balls", "Z_mech", "contacts_strong", "contacts_weak", "particles_strong",
                                "particles_weak", "fn_mean_N", "fn_strong_N", "fn_weak_N", "ft_mean_N", "ft_strong_N",
                                "ft_weak_N", "fn_ratio_strong_weak", "ft_ratio_strong_weak"};
  for (const char* net : {"", "_strong", "_weak"})
    for (const char* a : {"a_c", "a_n", "a_t"}) c.push_back(std::string(a) + net);
  for (const char* x : {"lw_sigma_zz_kPa", "lw_sigma_xx_kPa", "lw_sigma_yy_kPa", "lw_q_over_p", "sff_q_over_p",
                        "q_strong_kPa", "q_weak_kPa"})
    c.emplace_back(x);
  for (std::string& name : c) name = prefix + name;
  return c;
}

namespace {
/// Calls f on every field of a row, in one fixed order: the single list that saving and reading share.
template <class Row, class F>
void each_field(Row& r, F&& f) {
  f(r.z.z), f(r.z.z_balls), f(r.z.z_mech), f(r.z.on);
  f(r.net.threshold), f(r.net.fn_ratio), f(r.net.ft_ratio);
  for (auto* n : {&r.net.all, &r.net.strong, &r.net.weak})
    f(n->contacts), f(n->particles), f(n->mean_fn), f(n->mean_ft), f(n->stress);
  for (auto* a : {&r.all, &r.strong, &r.weak})
    f(a->contacts), f(a->fabric), f(a->ac), f(a->an), f(a->at), f(a->f0), f(a->a_c), f(a->a_n), f(a->a_t);
  f(r.stress), f(r.q_over_p), f(r.q_over_p_sff);
}
}  // namespace

void append_micro_state(const MicroRow& r, std::vector<double>& v) {
  MicroRow copy = r;
  each_field(copy, [&](auto& x) {
    using T = std::decay_t<decltype(x)>;
    if constexpr (std::is_same_v<T, std::vector<long>>) {
      v.push_back(static_cast<double>(x.size()));
      for (long n : x) v.push_back(static_cast<double>(n));
    } else if constexpr (std::is_same_v<T, Tensor>) {
      v.insert(v.end(), x.begin(), x.end());
    } else {
      v.push_back(static_cast<double>(x));
    }
  });
}

MicroRow micro_row_from(const std::vector<double>& v, std::size_t& at) {
  auto next = [&]() {
    if (at >= v.size()) throw std::runtime_error("checkpoint: the micro rows end early");
    if (!std::isfinite(v[at]))
      throw std::runtime_error("checkpoint: micro value " + std::to_string(at) + " is not a finite number");
    return v[at++];
  };
  // A count read from the file: a whole number no larger than what is left (a histogram's length, a count).
  auto count = [&](double most) {
    const double c = next();
    if (c < 0 || c > most || c != std::floor(c))
      throw std::runtime_error("checkpoint: micro value " + std::to_string(at - 1) + " = " + std::to_string(c) +
                               " is not a count (allowed: a whole number from 0 to " + std::to_string(most) + ")");
    return c;
  };
  MicroRow r;
  each_field(r, [&](auto& x) {
    using T = std::decay_t<decltype(x)>;
    if constexpr (std::is_same_v<T, std::vector<long>>) {
      x.resize(static_cast<std::size_t>(count(static_cast<double>(v.size() - at - 1))));
      for (long& n : x) n = static_cast<long>(count(9e15));
    } else if constexpr (std::is_same_v<T, Tensor>) {
      for (Real& e : x) e = next();
    } else if constexpr (std::is_integral_v<T>) {
      x = static_cast<T>(count(9e15));
    } else {
      x = static_cast<T>(next());
    }
  });
  return r;
}

std::vector<double> micro_values(const MicroRow& r) {
  std::vector<double> v = {r.z.z,
                           r.z.z_balls,
                           r.z.z_mech,
                           static_cast<double>(r.net.strong.contacts),
                           static_cast<double>(r.net.weak.contacts),
                           static_cast<double>(r.net.strong.particles),
                           static_cast<double>(r.net.weak.particles),
                           r.net.all.mean_fn,
                           r.net.strong.mean_fn,
                           r.net.weak.mean_fn,
                           r.net.all.mean_ft,
                           r.net.strong.mean_ft,
                           r.net.weak.mean_ft,
                           r.net.fn_ratio,
                           r.net.ft_ratio};
  for (const Anisotropy* a : {&r.all, &r.strong, &r.weak}) {
    v.push_back(a->a_c);
    v.push_back(a->a_n);
    v.push_back(a->a_t);
  }
  // Deviator of the partial (ball-ball) stresses: how the strong and weak networks share q.
  auto q_of = [](const Tensor& t) { return (t[8] - 0.5 * (t[0] + t[4])) / 1e3; };
  v.insert(v.end(), {r.stress[8] / 1e3, r.stress[0] / 1e3, r.stress[4] / 1e3, r.q_over_p, r.q_over_p_sff,
                     q_of(r.net.strong.stress), q_of(r.net.weak.stress)});
  return v;
}

void write_micro_state(const std::string& folder, const std::string& label, const ContactSet& s,
                       const ContactSet& rve, int rose_bins) {
  const Coordination za = coordination(s), zs = coordination(s, Network::kStrong), zw = coordination(s, Network::kWeak);
  const std::size_t nmax = std::max({za.on.size(), zs.on.size(), zw.on.size()});
  std::string t = "n,particles_all,particles_strong,particles_weak\n";
  auto at = [](const std::vector<long>& v, std::size_t k) { return k < v.size() ? v[k] : 0L; };
  char row[160];
  for (std::size_t k = 0; k < nmax; ++k) {
    std::snprintf(row, sizeof row, "%zu,%ld,%ld,%ld\n", k, at(za.on, k), at(zs.on, k), at(zw.on, k));
    t += row;
  }
  io::write_text_atomic(folder + "/micro_coordination_" + label + ".csv", t);
  const auto ra = rose(s, rose_bins), rs = rose(s, rose_bins, Network::kStrong), rw = rose(s, rose_bins, Network::kWeak);
  t = "theta_deg,density_all,fn_all_N,ft_all_N,density_strong,fn_strong_N,ft_strong_N,density_weak,fn_weak_N,"
      "ft_weak_N\n";
  for (int k = 0; k < rose_bins; ++k) {
    std::snprintf(row, sizeof row, "%.2f,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", ra[k].theta_deg, ra[k].density,
                  ra[k].mean_fn, ra[k].mean_ft, rs[k].density, rs[k].mean_fn, rs[k].mean_ft, rw[k].density,
                  rw[k].mean_fn, rw[k].mean_ft);
    t += row;
  }
  io::write_text_atomic(folder + "/micro_rose_" + label + ".csv", t);
  // The full tensors (row-major xx xy xz yx ... zz), for directions other than the axis.
  t = "network,tensor,xx,xy,xz,yx,yy,yz,zx,zy,zz\n";
  const Tensor stress = love_weber(s, 1.0, true);  // only its deviator's direction is used, for the signs
  for (const auto& [name, net] : {std::pair<const char*, Network>{"all", Network::kAll}, {"strong", Network::kStrong},
                                  {"weak", Network::kWeak}}) {
    const Anisotropy a = anisotropy(s, net, stress);
    for (const auto& [tn, tensor] : {std::pair<const char*, const Tensor*>{"fabric", &a.fabric}, {"a_c", &a.ac},
                                     {"a_n", &a.an}, {"a_t", &a.at}}) {
      t += std::string(name) + "," + tn;
      for (Real x : *tensor) {
        std::snprintf(row, sizeof row, ",%.6g", x);
        t += row;
      }
      t += "\n";
    }
  }
  io::write_text_atomic(folder + "/micro_tensors_" + label + ".csv", t);
  write_force_chains_vtk(folder + "/force_chains_" + label + ".vtk", rve);
}

Real surface_volume(const io::SurfaceSnapshot& surface) {
  const std::size_t n = surface.nodes.size() / 3;
  auto node = [&](int k) { return Vec3(surface.nodes[3 * k], surface.nodes[3 * k + 1], surface.nodes[3 * k + 2]); };
  Real z0 = INFINITY, z1 = -INFINITY;
  for (std::size_t k = 0; k < n; ++k) z0 = std::min(z0, node(k).z), z1 = std::max(z1, node(k).z);
  const Vec3 o(0, 0, z0);
  Real v = 0;
  for (std::size_t t = 0; t + 2 < surface.triangles.size(); t += 3) {
    const Vec3 a = node(surface.triangles[t]) - o, b = node(surface.triangles[t + 1]) - o,
               c = node(surface.triangles[t + 2]) - o;
    v += dot(a, cross(b, c)) / 6;
  }
  // Top cap: the ring of nodes at the top platen, ordered by angle, as a polygon; its cone from o.
  std::vector<std::pair<Real, Vec3>> ring;
  for (std::size_t k = 0; k < n; ++k)
    if (node(k).z > z1 - 1e-9 * std::max(Real(1e-3), z1 - z0)) ring.emplace_back(std::atan2(node(k).y, node(k).x), node(k));
  std::sort(ring.begin(), ring.end(), [](const auto& p, const auto& q) { return p.first < q.first; });
  Real area = 0;
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const Vec3& p = ring[k].second;
    const Vec3& q = ring[(k + 1) % ring.size()].second;
    area += 0.5 * (p.x * q.y - q.x * p.y);
  }
  return std::fabs(v) + area * (z1 - z0) / 3;
}


}  // namespace dem

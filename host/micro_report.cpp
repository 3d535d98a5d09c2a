#include "micro_report.hpp"

#include <algorithm>
#include <cstdio>

#include "io_hdf5.hpp"

namespace dem {

MicroRow micro_row(const ContactSet& s, Real volume) {
  MicroRow r;
  r.z = coordination(s);
  r.net = networks(s, volume);
  r.stress = love_weber(s, volume, true);
  r.all = anisotropy(s, Network::kAll, r.stress);
  r.strong = anisotropy(s, Network::kStrong, r.stress);
  r.weak = anisotropy(s, Network::kWeak, r.stress);
  const Real p = (r.stress[0] + r.stress[4] + r.stress[8]) / 3;
  const Real q = r.stress[8] - (r.stress[0] + r.stress[4]) / 2;
  r.q_over_p = p > 0 ? q / p : 0;
  r.q_over_p_sff = 0.4 * (r.all.a_c + r.all.a_n + 1.5 * r.all.a_t);
  return r;
}

std::vector<std::string> micro_columns(const std::string& prefix) {
  std::vector<std::string> c = {"Z", "Z_balls", "Z_mech", "contacts_strong", "contacts_weak", "particles_strong",
                                "particles_weak", "fn_mean_N", "fn_strong_N", "fn_weak_N", "ft_mean_N", "ft_strong_N",
                                "ft_weak_N", "fn_ratio_strong_weak", "ft_ratio_strong_weak"};
  for (const char* net : {"", "_strong", "_weak"})
    for (const char* a : {"a_c", "a_n", "a_t"}) c.push_back(std::string(a) + net);
  for (const char* x : {"lw_sigma_zz_kPa", "lw_sigma_xx_kPa", "lw_sigma_yy_kPa", "lw_q_over_p", "sff_q_over_p"})
    c.emplace_back(x);
  for (std::string& name : c) name = prefix + name;
  return c;
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
  v.insert(v.end(), {r.stress[8] / 1e3, r.stress[0] / 1e3, r.stress[4] / 1e3, r.q_over_p, r.q_over_p_sff});
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
  write_force_chains_vtk(folder + "/force_chains_" + label + ".vtk", rve);
}

}  // namespace dem

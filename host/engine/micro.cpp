#include "host/engine/micro.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "host/engine/stress.hpp"
#include "host/io/io_hdf5.hpp"

namespace dem {

namespace {

constexpr Real kPi = 3.14159265358979323846;

Tensor outer(const Vec3& a, const Vec3& b) {
  Tensor t;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t[3 * i + j] = a[i] * b[j];
  return t;
}

Tensor deviator(const Tensor& t) {
  Tensor d = t;
  const Real m = mean_stress(t);
  for (int i = 0; i < 3; ++i) d[4 * i] -= m;
  return d;
}

Real contract(const Tensor& a, const Tensor& b) {
  Real s = 0;
  for (int k = 0; k < 9; ++k) s += a[k] * b[k];
  return s;
}

Real quad(const Tensor& a, const Vec3& n) {
  Real s = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s += a[3 * i + j] * n[i] * n[j];
  return s;
}

Real mean_ball_fn(const ContactSet& s) {
  Real sum = 0;
  long n = 0;
  for (const ContactRecord& c : s.contacts)
    if (c.boundary == Boundary::kNone && c.in_volume) sum += c.fn, ++n;
  return n > 0 ? sum / n : 0;
}

/// Whether a contact is of the network (its volume membership aside).
bool of_network(const ContactRecord& c, Network net, Real threshold) {
  return net == Network::kAll || (net == Network::kStrong ? c.fn > threshold : c.fn <= threshold);
}

/// Contact averages use the contacts of the network inside the volume.
bool in_network(const ContactRecord& c, Network net, Real threshold) {
  return c.in_volume && of_network(c, net, threshold);
}

bool ball_inside(const ContactSet& s, int q) { return s.inside.empty() || s.inside[q]; }

}  // namespace

Coordination coordination(const ContactSet& s, Network net) {
  const std::size_t nball = s.radius.size();
  const Real threshold = mean_ball_fn(s);
  std::vector<int> counted(nball, 0), balls_only(nball, 0);
  long nc = 0, nbb = 0;
  for (const ContactRecord& c : s.contacts) {
    if (c.boundary == Boundary::kPlaten || !of_network(c, net, threshold)) continue;
    if (c.in_volume) ++nc, nbb += c.boundary == Boundary::kNone;
    ++counted[c.a];
    if (c.boundary == Boundary::kNone) {
      ++counted[c.b];
      ++balls_only[c.a];
      ++balls_only[c.b];
    }
  }
  Coordination z;
  long np = 0, n0 = 0, n1 = 0;
  int nmax = 0;
  for (std::size_t q = 0; q < nball; ++q) {
    if (!ball_inside(s, static_cast<int>(q))) continue;
    ++np;
    n0 += balls_only[q] == 0;
    n1 += balls_only[q] == 1;
    nmax = std::max(nmax, counted[q]);
  }
  if (np == 0) return z;
  // Every ball-ball contact has two ends, a membrane contact one ball end: Eq. 17 counts contacts, so
  // 2 Nc / Np with Nc = ball-ball + membrane contacts, as the paper's PFC count does.
  z.z = 2.0 * nc / np;
  z.z_balls = 2.0 * nbb / np;
  // Thornton's Z_m from the balls' own counts (each contact of a ball inside, wherever its point lies).
  long ends = 0;
  for (std::size_t q = 0; q < nball; ++q)
    if (ball_inside(s, static_cast<int>(q))) ends += balls_only[q];
  z.z_mech = np - n0 - n1 > 0 ? static_cast<Real>(ends - n1) / (np - n0 - n1) : 0;
  z.on.assign(nmax + 1, 0);
  for (std::size_t q = 0; q < nball; ++q)
    if (ball_inside(s, static_cast<int>(q))) ++z.on[counted[q]];
  return z;
}

Networks networks(const ContactSet& s, Real volume) {
  Networks w;
  w.threshold = mean_ball_fn(s);
  NetworkStats* sets[3] = {&w.all, &w.strong, &w.weak};
  const Network kinds[3] = {Network::kAll, Network::kStrong, Network::kWeak};
  for (int k = 0; k < 3; ++k) {
    NetworkStats& n = *sets[k];
    std::vector<char> touched(s.radius.size(), 0);
    for (const ContactRecord& c : s.contacts) {
      if (c.boundary != Boundary::kNone || !of_network(c, kinds[k], w.threshold)) continue;
      touched[c.a] = touched[c.b] = 1;
      if (!c.in_volume) continue;
      ++n.contacts;
      n.mean_fn += c.fn;
      n.mean_ft += norm(c.ft);
      add_love_weber(n.stress, c, volume);
    }
    for (std::size_t q = 0; q < touched.size(); ++q) n.particles += touched[q] && ball_inside(s, static_cast<int>(q));
    if (n.contacts > 0) {
      n.mean_fn /= n.contacts;
      n.mean_ft /= n.contacts;
    }
  }
  w.fn_ratio = w.weak.mean_fn > 0 ? w.strong.mean_fn / w.weak.mean_fn : 0;
  w.ft_ratio = w.weak.mean_ft > 0 ? w.strong.mean_ft / w.weak.mean_ft : 0;
  return w;
}

Real signed_magnitude(const Tensor& a, const Tensor& reference) {
  Tensor sref = deviator(reference);
  if (contract(sref, sref) == 0) sref = {-1, 0, 0, 0, -1, 0, 0, 0, 2};  // compression along z
  const Real m = std::sqrt(1.5 * contract(a, a));
  return contract(a, sref) < 0 ? -m : m;
}

Anisotropy anisotropy(const ContactSet& s, Network net, const Tensor& reference) {
  const Real threshold = mean_ball_fn(s);
  Anisotropy a;
  std::vector<const ContactRecord*> cs;
  for (const ContactRecord& c : s.contacts)
    if (c.boundary == Boundary::kNone && in_network(c, net, threshold)) cs.push_back(&c);
  a.contacts = static_cast<long>(cs.size());
  if (cs.empty()) return a;
  for (const ContactRecord* c : cs) {
    const Tensor t = outer(c->normal, c->normal);
    for (int q = 0; q < 9; ++q) a.fabric[q] += t[q] / cs.size();
  }
  const Tensor fd = deviator(a.fabric);
  for (int q = 0; q < 9; ++q) a.ac[q] = 7.5 * fd[q];
  // Average force tensors, each contact weighted by 1 / E(n) relative to isotropy (Ouadfel & Rothenburg).
  Tensor chi_n{}, chi_t{};
  for (const ContactRecord* c : cs) {
    // A strongly aligned set (a strong network: a_c of 2 or more) makes the second-order density
    // 1 + a^c:nn small or negative across the axis, where it no longer describes the set: the floor keeps
    // those contacts' weights finite (at most 10 times the isotropic one).
    const Real w = 1 / (cs.size() * std::max(1 + quad(a.ac, c->normal), Real(0.1)));
    const Tensor tn = outer(c->normal, c->normal), tt = outer(c->ft, c->normal);
    for (int q = 0; q < 9; ++q) {
      chi_n[q] += w * c->fn * tn[q];
      chi_t[q] += w * tt[q];
    }
  }
  a.f0 = chi_n[0] + chi_n[4] + chi_n[8];
  if (a.f0 > 0) {
    const Tensor dn = deviator(chi_n);
    // The tangential tensor is used symmetrised: its antisymmetric part carries no stress (moment balance).
    Tensor st;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) st[3 * i + j] = 0.5 * (chi_t[3 * i + j] + chi_t[3 * j + i]);
    const Tensor dt = deviator(st);
    for (int q = 0; q < 9; ++q) {
      a.an[q] = 7.5 * dn[q] / a.f0;
      a.at[q] = 5.0 * dt[q] / a.f0;
    }
  }
  a.a_c = signed_magnitude(a.ac, reference);
  a.a_n = signed_magnitude(a.an, reference);
  a.a_t = signed_magnitude(a.at, reference);
  return a;
}

std::vector<RoseBin> rose(const ContactSet& s, int bins, Network net) {
  if (bins < 1) throw std::invalid_argument("rose: bins must be >= 1");
  const Real threshold = mean_ball_fn(s);
  std::vector<RoseBin> r(bins);
  long total = 0;
  // Bins of equal solid angle (equal steps in cos theta): an isotropic set fills them equally, so the bins
  // near the axis are as well sampled as those at the equator.
  auto bin_of = [&](Real cos_theta) { return std::clamp(static_cast<int>((1 - cos_theta) / 2 * bins), 0, bins - 1); };
  for (const ContactRecord& c : s.contacts) {
    if (c.boundary != Boundary::kNone || !in_network(c, net, threshold)) continue;
    ++total;
    const Real ct = std::clamp(c.normal.z, Real(-1), Real(1));
    for (Real t : {ct, -ct}) {  // n and -n: each contact counts twice with weight 1/2
      RoseBin& b = r[bin_of(t)];
      b.count += 1;
      b.mean_fn += c.fn;
      b.mean_ft += norm(c.ft);
    }
  }
  const Real solid = 4 * kPi / bins;
  for (int k = 0; k < bins; ++k) {
    r[k].theta_deg = std::acos(1 - (2 * k + 1.0) / bins) * 180 / kPi;
    r[k].density = total > 0 ? 0.5 * r[k].count / (total * solid) : 0;
    if (r[k].count > 0) {
      r[k].mean_fn /= r[k].count;
      r[k].mean_ft /= r[k].count;
    }
    r[k].count /= 2;
  }
  return r;
}

Real sff_stress_ratio(const Anisotropy& a) {
  Tensor sum;
  for (int q = 0; q < 9; ++q) sum[q] = a.ac[q] + a.an[q] + 1.5 * a.at[q];
  return 0.4 * axial_deviator(sum);
}

ContactSet restrict_to_cube(const ContactSet& s, const Vec3& centre, Real edge) {
  Real lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (int d = 0; d < 3 && !s.x.empty(); ++d) lo[d] = hi[d] = s.x[0][d];
  for (std::size_t q = 0; q < s.x.size(); ++q)
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], s.x[q][d] - s.radius[q]);
      hi[d] = std::max(hi[d], s.x[q][d] + s.radius[q]);
    }
  for (int d = 0; d < 3; ++d)
    if (!(edge > 0) || centre[d] - edge / 2 < lo[d] || centre[d] + edge / 2 > hi[d]) {
      std::ostringstream m;
      m << "representative volume: a cube of edge " << edge * 1e3 << " mm centred at (" << centre.x * 1e3 << ", "
        << centre.y * 1e3 << ", " << centre.z * 1e3 << ") mm does not fit in the specimen, which spans (" << lo[0] * 1e3
        << ".." << hi[0] * 1e3 << ", " << lo[1] * 1e3 << ".." << hi[1] * 1e3 << ", " << lo[2] * 1e3 << ".."
        << hi[2] * 1e3 << ") mm";
      throw std::invalid_argument(m.str());
    }
  auto inside = [&](const Vec3& p) {
    for (int d = 0; d < 3; ++d)
      if (std::fabs(p[d] - centre[d]) > edge / 2) return false;
    return true;
  };
  ContactSet r;
  r.x = s.x;
  r.radius = s.radius;
  r.inside.assign(s.x.size(), 0);
  for (std::size_t q = 0; q < s.x.size(); ++q) r.inside[q] = ball_inside(s, static_cast<int>(q)) && inside(s.x[q]);
  for (ContactRecord c : s.contacts) {
    c.in_volume = c.in_volume && inside(c.point);
    if (c.in_volume || r.inside[c.a] || (c.b >= 0 && r.inside[c.b])) r.contacts.push_back(c);
  }
  return r;
}

void write_force_chains_vtk(const std::string& path, const ContactSet& s) {
  const Real threshold = mean_ball_fn(s);
  std::vector<const ContactRecord*> cs;
  for (const ContactRecord& c : s.contacts)
    if (c.boundary == Boundary::kNone && c.in_volume) cs.push_back(&c);
  std::ostringstream o;
  o.precision(9);
  o << "# vtk DataFile Version 3.0\ntriaxdem force chains: segments between ball centres\nASCII\n"
       "DATASET POLYDATA\nPOINTS "
    << 2 * cs.size() << " double\n";
  for (const ContactRecord* c : cs) {
    const Vec3& a = s.x[c->a];
    const Vec3 b = a + c->branch;
    o << a.x << " " << a.y << " " << a.z << "\n" << b.x << " " << b.y << " " << b.z << "\n";
  }
  o << "LINES " << cs.size() << " " << 3 * cs.size() << "\n";
  for (std::size_t k = 0; k < cs.size(); ++k) o << "2 " << 2 * k << " " << 2 * k + 1 << "\n";
  o << "CELL_DATA " << cs.size() << "\nSCALARS normal_force_N double 1\nLOOKUP_TABLE default\n";
  for (const ContactRecord* c : cs) o << c->fn << "\n";
  o << "SCALARS strong int 1\nLOOKUP_TABLE default\n";
  for (const ContactRecord* c : cs) o << (c->fn > threshold ? 1 : 0) << "\n";
  io::write_text_atomic(path, o.str());
}

}  // namespace dem

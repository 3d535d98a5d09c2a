/// Reference results of the jobs (tests/reference.hpp): small cases of what users run, whose key results are
/// kept in tests/reference/*.csv. A halved strength, a membrane that depends on the thread count or a layer
/// compacted to another density changes their bits and, unless it is a change of rounding only, leaves the
/// population that the scatter rows describe.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "host/engine/builder.hpp"
#include "host/fit/calibrate.hpp"
#include "host/config/model_keys.hpp"
#include "host/data/curve_reading.hpp"
#include "host/fit/diagnose.hpp"
#include "host/triax/micro_report.hpp"
#include "host/lab/periodic_lab.hpp"
#include "host/engine/simulation.hpp"
#include "host/triax/triaxial.hpp"
#include "reference.hpp"
#include "test_util.hpp"

using namespace dem;

namespace {

/// "q_at_1pct" style names of the strains that curves are read at (percent, '.' as 'p').
std::string at(const std::string& what, Real strain_pct) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", strain_pct);
  std::string s = buf;
  for (char& c : s)
    if (c == '.') c = 'p';
  return what + "_at_" + s + "pct";
}

/// The curves and summary of a simulated test, q in units of sigma3.
void add_curves(std::map<std::string, double>& v, const TriaxialTest& t, const std::vector<Real>& strains_pct) {
  for (Real e : strains_pct) {
    v[at("q_over_sigma3", e)] = curve_value(t.eps_a, t.q, e / 100) / t.sigma3;
    v[at("eps_v_pct", e)] = 100 * curve_value(t.eps_a, t.eps_v, e / 100);
  }
  v["q_peak_over_sigma3"] = t.q_peak / t.sigma3;
  v["eps_a_peak_pct"] = 100 * t.eps_a_peak;
  v["q_end_over_sigma3"] = t.q_end / t.sigma3;
  v["max_dilatancy"] = t.max_dilatancy;
}

/// The periodic cell of the calibration simulator (tests/data/hidden_effects.toml: 120 balls, 8% strain) at
/// 100 kPa, with the base law and with each model extension at the strength of its hidden-effect test.
test::CaseResults periodic_cell(unsigned seed) {
  const Config cfg = load_config(std::string(TRIAXDEM_SOURCE_DIR) + "/tests/data/hidden_effects.toml");
  PeriodicLab lab(cfg, false, 1, seed);
  std::map<std::string, double> v;
  const TriaxialTest base = lab.run(model_of(cfg), 100e3);
  add_curves(v, base, {0.1, 1, 2, 5, 8});
  v["void_ratio_sheared"] = base.void_ratio;
  const std::map<std::string, Real> strength{
      {"hertz", 3e-3}, {"roughness", 1e-2}, {"wear", 0.6}, {"twist", 0.2}, {"adhesion", 3e4}, {"membrane", 300e3}};
  test::CaseResults out{{"periodic_cell", v}};
  std::map<std::string, double> ext;
  // Every extension of the table, whether the diagnosis tries it or not.
  for (const ModelKey& k : model_keys()) {
    if (!*k.extension) continue;
    const std::string name = k.extension;
    Model m = model_of(cfg);
    set_param(m, k.key, strength.at(name));
    const TriaxialTest t = lab.run(m, 100e3);
    ext[name + "_" + at("q_over_sigma3", 1)] = curve_value(t.eps_a, t.q, 0.01) / t.sigma3;
    ext[name + "_q_peak_over_sigma3"] = t.q_peak / t.sigma3;
    ext[name + "_q_end_over_sigma3"] = t.q_end / t.sigma3;
    ext[name + "_" + at("eps_v_pct", 8)] = 100 * curve_value(t.eps_a, t.eps_v, 0.08);
  }
  out["periodic_extensions"] = ext;
  return out;
}

/// The membrane triaxial test of tests/test_triaxial.cpp's tiny specimen (16 mm, 3 layers, 24 x 8 membrane,
/// I = 1e-2) to 5% strain: the specimen's layers, the shear curves and the micro measures at the peak record.
test::CaseResults membrane_triaxial(unsigned seed) {
  Config c = test::tiny_triaxial_config(0.3, 0.02);
  c.run.seed = seed;
  c.triaxial.axial_strain_end = 0.05;
  const Specimen sp = build_specimen(c, false);
  std::map<std::string, double> layers;
  for (std::size_t k = 0; k < sp.layers.size(); ++k)
    layers["layer" + std::to_string(k + 1) + "_void_ratio"] = sp.layers[k].void_ratio;
  layers["void_ratio"] = sp.void_ratio;
  layers["height_mm"] = 1e3 * sp.height;
  layers["balls"] = static_cast<double>(sp.balls.size());

  const TriaxialResult r = run_triaxial(c, sp, nullptr, false);
  TriaxialTest t;
  t.sigma3 = c.triaxial.sigma3;
  for (const TriaxialRecord& x : r.records) {
    t.eps_a.push_back(x.eps_a);
    t.q.push_back(x.q);
    t.eps_v.push_back(x.eps_v);
  }
  std::map<std::string, double> shear;
  for (Real e : {0.5, 1.0, 2.0, 4.0}) {
    shear[at("q_over_sigma3", e)] = curve_value(t.eps_a, t.q, e / 100) / t.sigma3;
    shear[at("eps_v_pct", e)] = 100 * curve_value(t.eps_a, t.eps_v, e / 100);
  }
  shear["q_peak_over_sigma3"] = r.q_peak / t.sigma3;
  shear["void_ratio_consolidated"] = r.void_ratio_consolidated;
  shear["escaped"] = r.escaped;
  shear["lateral_stress_end_over_sigma3"] = r.records.back().sigma3_balls / t.sigma3;

  std::map<std::string, double> micro;
  const MicroRow& m = r.micro.at(r.highest_record);
  micro["z"] = m.z.z;
  micro["z_mech"] = m.z.z_mech;
  micro["a_c"] = m.all.a_c;
  micro["a_n"] = m.all.a_n;
  micro["a_t"] = m.all.a_t;
  micro["strong_contacts_share"] =
      static_cast<double>(m.net.strong.contacts) / static_cast<double>(m.net.all.contacts);
  micro["fn_strong_over_weak"] = m.net.fn_ratio;
  micro["q_over_p"] = m.q_over_p;
  return {{"specimen_layers", layers}, {"membrane_triaxial", shear}, {"micro_record", micro}};
}

/// Two spheres in an oblique collision with a spinning partner, through the whole time loop, for each contact law:
/// the velocities and spins after they part. No packing: the seed changes nothing, and only bits are kept.
test::CaseResults contact_laws(unsigned) {
  struct Law {
    std::string name;
    ContactParams p;
  };
  ContactParams linear = test::law(1e8, 1.5, 0.3, 0.05, 0.2);
  std::vector<Law> laws{{"linear", linear}};
  ContactParams hertz = linear, rough = linear, wear = linear, twist = linear, adhesion = linear;
  hertz.hertz_overlap = 3e-3;
  rough.roughness = 1e-2;
  wear.wear = 0.6;
  twist.twist = 0.2;
  adhesion.adhesion = 3e4;
  laws.push_back({"hertz", hertz});
  laws.push_back({"roughness", rough});
  laws.push_back({"wear", wear});
  laws.push_back({"twist", twist});
  laws.push_back({"adhesion", adhesion});
  std::map<std::string, double> v;
  for (const Law& law : laws) {
    const Real R = 1e-3;
    std::vector<BallSpec> b(2);
    b[0].x = Vec3(-R - 1e-6, 0.3 * R, 0);
    b[1].x = Vec3(R + 1e-6, -0.3 * R, 0);
    b[0].v = Vec3(0.5, 0, 0.1);
    b[1].v = Vec3(-0.5, 0, 0);
    b[1].w = Vec3(0, 0, 200);
    b[0].radius = b[1].radius = R;
    b[0].density = b[1].density = 2500;
    SimParams prm;
    prm.skin = 0.1 * R;
    prm.integ.alpha = 0;
    prm.integ.gravity = Vec3();
    Simulation sim(make_particles(b), make_walls({}), FacetMesh(), {law.p}, 1, prm);
    sim.set_dt(0.2 * sim.critical_dt());
    for (int s = 0; s < 4000; ++s) sim.step();
    const HostParticles h = to_host_by_gid(sim.particles());
    const char* axes = "xyz";
    for (int d = 0; d < 3; ++d) {
      v[law.name + "_v0" + axes[d]] = h.v[0][d];
      v[law.name + "_w0" + axes[d]] = h.w[0][d];
      v[law.name + "_w1" + axes[d]] = h.w[1][d];
    }
  }
  return {{"contact_laws", v}};
}

}  // namespace

TEST(Reference, PeriodicCell) {
  test::check_reference(periodic_cell,
                        {{"periodic_cell",
                          {"q_over_sigma3_at_1pct", "q_peak_over_sigma3", "q_end_over_sigma3", "eps_v_pct_at_8pct",
                           "void_ratio_sheared"}},
                         {"periodic_extensions",
                          {"hertz_q_peak_over_sigma3", "roughness_q_peak_over_sigma3", "wear_q_end_over_sigma3",
                           "twist_q_peak_over_sigma3", "adhesion_q_peak_over_sigma3", "membrane_q_end_over_sigma3"}}});
}

TEST(Reference, MembraneTriaxial) {
  test::check_reference(membrane_triaxial,
                        {{"specimen_layers", {"layer1_void_ratio", "layer2_void_ratio", "layer3_void_ratio"}},
                         {"membrane_triaxial",
                          {"q_over_sigma3_at_1pct", "q_peak_over_sigma3", "eps_v_pct_at_4pct",
                           "void_ratio_consolidated"}},
                         {"micro_record", {"z", "a_c", "a_n", "a_t"}}});
}

TEST(Reference, ContactLaws) { test::check_reference(contact_laws, {}); }

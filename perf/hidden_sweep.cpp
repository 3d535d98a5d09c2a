/// Identification sweep of the diagnosis: for each hidden extension (and none) and each seed, draws
/// the strength from the seed over the extension's whole physical range (draw_strength), generates noisy
/// synthetic data, diagnoses them and records the verdict. Prints the confusion matrix (rows: hidden, columns:
/// named) and the rate of correct answers, and writes one CSV row per case.
///
///   ./build/perf/hidden_sweep --first-seed 1 --last-seed 4 -j 2 -o runs/hidden_sweep.csv
///
/// About 1.5 minutes a case on 2 cores with the default simulator (tests/data/hidden_effects.toml). Each seed
/// draws the same quantile of every extension's range (log-uniform), so a row compares the extensions at the
/// same relative strength.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <Kokkos_Core.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/fit/calibrate.hpp"
#include "host/config/config.hpp"
#include "host/fit/diagnose.hpp"
#include "host/util/forked_runs.hpp"
#include "host/util/process_pool.hpp"
#include "host/util/progress.hpp"
#include "host/util/ranks.hpp"

using namespace dem;

int main(int argc, char** argv) {
  // Under mpirun or srun the diagnoses' runs spread over the ranks, as triaxdem diagnose's do (host/util/ranks.hpp).
  try {
    ranks::start(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hidden_sweep: %s\n", e.what());
    return 1;
  }
  struct RanksEnd {
    ~RanksEnd() { ranks::stop(); }
  } ranks_end;
  const auto t0 = std::chrono::steady_clock::now();
  CLI::App app("triaxdem hidden-effect identification sweep");
  std::string config = std::string(TRIAXDEM_SOURCE_DIR) + "/tests/data/hidden_effects.toml";
  std::string out = "hidden_sweep.csv";
  unsigned first = 1, last = 4;
  std::vector<unsigned> listed;
  int workers = 2;
  app.add_option("--config", config, "base config of the simulator")->check(CLI::ExistingFile);
  app.add_option("--first-seed", first, "first seed");
  app.add_option("--last-seed", last, "last seed");
  app.add_option("--seeds", listed, "these seeds instead of first..last (e.g. the upper quantiles: seed 6 "
                                    "draws 0.90 of each range, 9: 0.71, 10: 0.96, 12: 0.75)")->delimiter(',');
  app.add_option("-j,--jobs", workers, "simulator runs at once, one thread each");
  app.add_option("-o,--output", out, "CSV of the cases");
  bool own = false;
  double noise = 1;
  app.add_option("--noise-scale", noise, "the synthetic data's lab-like noise times this (0: as precise as a "
                 "simulation; default 1)");
  std::vector<std::string> hidden{"none"};
  for (const Extension& e : extensions()) hidden.push_back(e.name);
  std::vector<std::string> only;
  app.add_option("--hidden", only, "only these hidden effects (default all)")
      ->delimiter(',')
      ->check(CLI::IsMember(hidden));
  std::string ensemble;
  app.add_option("--ensemble", ensemble, "the diagnosis's ensemble instead of the config's: a number of specimens, "
                 "or auto (chosen from the measured scatter, the cell grown where that falls short)")
      ->check(CLI::IsMember({"auto"}) | CLI::Range(1, 64));
  double strain_pct = 0;
  app.add_option("--axial-strain-pct", strain_pct, "end every test at this axial strain instead of the config's "
                 "(the paper's tests end at 15%; the CI's simulator at 8%)")->check(CLI::Range(1.0, 30.0));
  int data_cell = kGeneratorCellFactor;
  app.add_option("--data-cell-factor", data_cell, "the data's specimens have this many times the simulator's balls "
                 "(default " + std::to_string(kGeneratorCellFactor) + ")")->check(CLI::Range(1, 64));
  app.add_flag("--own-specimen", own, "generate the data on the diagnosis's own first specimen (the old, easier test)");
  int cases_at_once = 1;
  app.add_option("--cases-at-once", cases_at_once, "cases run side by side, each a child process whose diagnosis runs "
                 "one run at a time (-j is then unused; under mpirun the ranks take the cases, one each at a time)")
      ->check(CLI::Range(1, 512));
  CLI11_PARSE(app, argc, argv);
  // Cases side by side (or spread over ranks): each a diagnosis in a child of one thread, its own runs one at a time.
  // The sweep's diagnoses hold few runs per pool, so cases, not runs, are what many workers can share.
  const bool case_pool = cases_at_once > 1 || ranks::spread();
  if (case_pool) {
    workers = 1;
    prepare_parallel_runs(2);
    ranks::quiet_shadows();
  } else {
    prepare_parallel_runs(workers);
  }
  Kokkos::ScopeGuard guard(argc, argv);
  Config cfg = load_config(config);
  if (ensemble == "auto") cfg.calibrate.ensemble = kAutoEnsemble;
  else if (!ensemble.empty()) cfg.calibrate.ensemble = std::stol(ensemble);
  if (strain_pct > 0) cfg.periodic.triax.target_strain = strain_pct / 100;
  const Model base = model_of(cfg);
  const std::vector<FreeParam> free{free_param("mu_s", base), free_param("mu_r", base)};
  // "none" first at every seed: the other cases of a seed share its data specimens and are compared with it.
  std::vector<std::string> run;
  for (const std::string& h : hidden)
    if (only.empty() || std::find(only.begin(), only.end(), h) != only.end()) run.push_back(h);
  std::map<std::string, std::map<std::string, int>> confusion;
  // Per hidden extension: the strengths named right and those missed or misnamed, for the detection-power table.
  std::map<std::string, std::vector<Real>> found, missed;
  // Cases whose data show the hidden effect at all: the hidden extension itself, fitted, passes both tests of the
  // verdict. Where it does not, no diagnosis under this rule could name it: the data, not the search, fall short.
  int shown = 0, shown_right = 0;
  std::vector<std::string> mixups;  // wrong names, with both extensions' evidence
  // What a hidden effect leaves once the base model is recalibrated: the base chi2 above that of the null case of the
  // same seed (the same data specimens, nothing hidden), set against the null cases' spread across seeds: what
  // changing the data specimens alone does.
  std::map<unsigned, Real> null_chi2;
  struct Residue {
    std::string hidden;
    Real strength, over_null;
    bool named;
  };
  std::vector<Residue> residues;
  std::ofstream csv(ranks::leader() ? out : "/dev/null");  // the leader writes
  // Every extension's BIC gain and held-out chi2 too, so that a decision rule can be judged on the whole sweep.
  csv << "hidden,strength,seed,verdict,base_chi2,chi2_limit,base_heldout,true_heldout,data_show,base_chi2_over_null";
  for (const Extension& e : extensions()) csv << "," << e.name << "_bic_gain," << e.name << "_heldout";
  // The recalibrated base parameters: what absorbs a hidden effect the verdict does not name.
  for (const FreeParam& p : free) csv << ",base_" << p.name;
  // The best generic discrepancy, every extension's rival (its shape, BIC gain and held-out chi2): what took a name
  // the data show away, where the verdict gives none.
  csv << ",rival_shape,rival_gain,rival_heldout\n";
  std::vector<unsigned> seeds = listed;
  for (unsigned s = first; listed.empty() && s <= last; ++s) seeds.push_back(s);
  struct Case {
    unsigned seed;
    std::string hidden;
  };
  std::vector<Case> cases;
  for (unsigned seed : seeds)
    for (const std::string& h : run) cases.push_back({seed, h});
  // One case's diagnosis, as text: verdict, then strength, chi2s and held-out values, then each fit's name, BIC and
  // held-out chi2, then the base values. Reals as %a, so that a case run in a child comes back to the bit.
  auto diagnose_case = [&](const Case& c) {
    Model truth = base;
    Real strength = 0;
    if (c.hidden != "none") set_param(truth, extension(c.hidden).param, strength = draw_strength(extension(c.hidden), c.seed));
    // The data come from a specimen per pressure that the diagnosis never runs (own: its first member, as before).
    PeriodicLab generator(own ? cfg : larger_cell(cfg, data_cell), false, own ? 1 : 3,
                          own ? cfg.run.seed : cfg.run.seed + kForeignSeedOffset + 3 * c.seed, 0, workers);
    const std::vector<TriaxialTest> data =
        synthetic_tests(generator, truth, {100e3, 200e3, 300e3}, "hidden", c.seed, noise);
    StateMatch state;  // the data's void ratio sets the preparation, as triaxdem diagnose does
    PeriodicLab matched(matched_state(cfg, data, state, false, match_plan(cfg, workers)), false, workers);
    const Diagnosis dg = diagnose(matched, base, free, data, measure_misfit(matched, base, data, NoiseOptions()), false);
    std::string t = dg.verdict + "\n";
    char num[64];
    auto put = [&](double v) {
      std::snprintf(num, sizeof num, "%a ", v);
      t += num;
    };
    for (double v : {double(strength), double(dg.base.best.chi2), double(dg.chi2_limit), double(dg.base_heldout),
                     double(dg.base_bic)})
      put(v);
    t += "\n";
    for (const ExtensionFit& f : dg.fits) {
      t += f.ext.name + " " + (f.accepted ? "1 " : "0 ");
      put(f.bic);
      put(f.heldout);
    }
    t += "\n";
    for (Real v : dg.base.values) put(v);
    t += "\n";
    if (const GenericFit* rival = generic_rival(dg.generic)) {
      std::string shape = rival->shape.name;
      std::replace(shape.begin(), shape.end(), ' ', '~');  // one token on its line
      t += shape + " ";
      put(dg.base_bic - rival->bic);
      put(rival->heldout);
    }
    return t + "\n";
  };
  // A case's row and its share of the tables, in case order as the cases end: "none" comes first at every seed, and
  // the others are set against it.
  std::vector<std::string> results(cases.size());
  auto emit = [&](std::size_t j) {
    const std::string& h = cases[j].hidden;
    const unsigned seed = cases[j].seed;
    std::istringstream in(results[j]);
    std::string verdict, line;
    std::getline(in, verdict);
    auto real = [](std::istream& is) {
      std::string tok;
      is >> tok;
      return static_cast<Real>(std::strtod(tok.c_str(), nullptr));
    };
    std::getline(in, line);
    std::istringstream nums(line);
    const Real strength = real(nums), base_chi2 = real(nums), chi2_limit = real(nums), base_heldout = real(nums),
               base_bic = real(nums);
    struct Fit {
      std::string name;
      bool accepted;
      Real bic, heldout;
    };
    std::vector<Fit> fits;
    std::getline(in, line);
    std::istringstream fl(line);
    for (Fit f; fl >> f.name;) {
      int acc = 0;
      fl >> acc;
      f.accepted = acc != 0;
      f.bic = real(fl);
      f.heldout = real(fl);
      fits.push_back(f);
    }
    std::getline(in, line);
    std::istringstream bl(line);
    std::vector<Real> base_values;
    for (std::size_t k = 0; k < free.size(); ++k) base_values.push_back(real(bl));
    std::getline(in, line);
    std::istringstream rl(line);
    std::string rival;
    rl >> rival;
    const Real rival_gain = real(rl), rival_heldout = real(rl);
    Real true_heldout = base_heldout;
    bool data_show = false;
    for (const Fit& f : fits)
      if (f.name == h) true_heldout = f.heldout, data_show = f.accepted;
    // A tie ("a or b") counts for the first named; the CSV keeps the whole verdict.
    const std::string named = verdict.substr(0, verdict.find(' '));
    ++confusion[h][named];
    if (h != "none") (named == h ? found : missed)[h].push_back(strength);
    shown += data_show;  // never for "none": no extension has that name
    shown_right += data_show && named == h;
    if (named != h && named != "none") {
      std::string text = h + " " + std::to_string(strength) + " named " + named + ":";
      for (const Fit& f : fits)
        if (f.name == h || f.name == named)
          text += " " + f.name + " BIC gain " + std::to_string(base_bic - f.bic) + ", held-out " +
                  std::to_string(base_heldout) + " -> " + std::to_string(f.heldout) + ";";
      mixups.push_back(text);
    }
    if (h == "none") null_chi2[seed] = base_chi2;
    const bool has_null = null_chi2.count(seed) > 0;
    const Real over_null = has_null ? base_chi2 - null_chi2[seed] : 0;
    if (h != "none" && has_null) residues.push_back({h, strength, over_null, named == h});
    char row[256];
    std::snprintf(row, sizeof row, "%s,%.4g,%u,%s,%.2f,%.2f,%.2f,%.2f,%d,", h.c_str(), strength, seed,
                  verdict.c_str(), base_chi2, chi2_limit, base_heldout, true_heldout, data_show);
    csv << row;
    if (has_null) {
      std::snprintf(row, sizeof row, "%.2f", over_null);
      csv << row;
    }
    for (const Fit& f : fits) {
      std::snprintf(row, sizeof row, ",%.2f,%.2f", base_bic - f.bic, f.heldout);
      csv << row;
    }
    for (std::size_t k = 0; k < free.size(); ++k) {
      std::snprintf(row, sizeof row, ",%.4g", free[k].shown * base_values[k]);
      csv << row;
    }
    std::replace(rival.begin(), rival.end(), '~', ' ');
    if (rival.empty()) {
      csv << ",,,";
    } else {
      std::snprintf(row, sizeof row, ",%s,%.2f,%.2f", rival.c_str(), rival_gain, rival_heldout);
      csv << row;
    }
    csv << "\n" << std::flush;
  };
  std::size_t next_row = 0;
  Progress progress("hidden sweep", static_cast<long>(cases.size()));
  long done = 0;
  auto case_done = [&](std::size_t j) {
    progress.update(++done, cases[j].hidden + " -> " + results[j].substr(0, results[j].find('\n')));
    while (next_row < cases.size() && !results[next_row].empty()) emit(next_row++);
  };
  if (case_pool) {
    PoolWork w;
    w.pieces = cases.size();
    w.workers = cases_at_once;
    w.child = [&](std::size_t j, int fd) {
      const std::string t = diagnose_case(cases[j]);
      put_bytes(fd, t.data(), t.size());
    };
    w.collect = [&](std::size_t j, int fd) {
      char buf[4096];
      results[j].clear();
      for (ssize_t r; (r = ::read(fd, buf, sizeof buf)) > 0;) results[j].append(buf, static_cast<std::size_t>(r));
      return !results[j].empty();
    };
    w.after = [&](std::size_t j, int status) {
      if (status != 0)
        throw std::runtime_error("hidden_sweep: the case " + cases[j].hidden + ", seed " + std::to_string(cases[j].seed) +
                                 " failed (exit status " + std::to_string(status) + ")");
      case_done(j);
    };
    run_pool(w, "hidden sweep");
  } else {
    for (std::size_t j = 0; j < cases.size(); ++j) {
      results[j] = diagnose_case(cases[j]);
      case_done(j);
    }
  }
  progress.finish("");
  std::printf("\nconfusion matrix (rows: hidden effect, columns: named by diagnose), %zu seeds:\n%-10s", seeds.size(),
              "hidden");
  for (const std::string& n : hidden) std::printf(" %9s", n.c_str());
  std::printf(" %8s\n", "correct");
  int right = 0, total = 0;
  for (const std::string& h : hidden) {
    std::printf("%-10s", h.c_str());
    int row = 0;
    for (const std::string& n : hidden) {
      std::printf(" %9d", confusion[h][n]);
      row += confusion[h][n];
    }
    std::printf(" %7.0f%%\n", row ? 100.0 * confusion[h][h] / row : 0.0);
    right += confusion[h][h];
    total += row;
  }
  std::printf("identified %d of %d cases (%.0f%%); cases in %s\n", right, total, 100.0 * right / total, out.c_str());
  int nulls = 0;  // cases with nothing hidden
  for (const auto& [named, n] : confusion["none"]) nulls += n;
  std::printf("the data show the hidden effect (the extension itself, fitted, lowers BIC and the held-out chi2 by "
              "%.0f) in %d of %d cases with one; %d of those named right\n", kStrongEvidence, shown, total - nulls,
              shown_right);
  std::printf("\ndetection power (noise scale %g): per extension, the smallest strength named right and the largest "
              "missed or misnamed\n%-10s %14s %14s %6s\n", noise, "hidden", "smallest found", "largest missed", "found");
  for (const Extension& e : extensions()) {
    const std::vector<Real>& f = found[e.name];
    const std::vector<Real>& m = missed[e.name];
    std::printf("%-10s %14s %14s %3zu/%zu\n", e.name.c_str(),
                f.empty() ? "-" : std::to_string(*std::min_element(f.begin(), f.end())).c_str(),
                m.empty() ? "-" : std::to_string(*std::max_element(m.begin(), m.end())).c_str(), f.size(),
                f.size() + m.size());
  }
  for (const std::string& l : mixups) std::printf("told apart wrongly: %s\n", l.c_str());
  if (null_chi2.size() >= 2 && !residues.empty()) {
    Real mean = 0, var = 0;
    for (const auto& [seed, c] : null_chi2) mean += c / static_cast<Real>(null_chi2.size());
    for (const auto& [seed, c] : null_chi2) var += (c - mean) * (c - mean) / static_cast<Real>(null_chi2.size() - 1);
    std::printf("\nwhat each hidden effect leaves once the base model is recalibrated: its base chi2 above the null "
                "case's on the same data specimens,\nagainst the spread of the null cases' base chi2 across seeds "
                "(sd %.1f: what changing the data specimens alone does)\n%-10s %12s %14s %s\n",
                std::sqrt(var), "hidden", "strength", "chi2 over null", "named right");
    std::sort(residues.begin(), residues.end(), [](const Residue& a, const Residue& b) {
      return a.hidden != b.hidden ? a.hidden < b.hidden : a.strength < b.strength;
    });
    for (const Residue& r : residues)
      std::printf("%-10s %12.4g %14.1f %s\n", r.hidden.c_str(), r.strength, r.over_null, r.named ? "yes" : "no");
  }
  // Each pool's pieces and their run times: tools/schedule_projection.py projects the sweep on more ranks from it.
  if (ranks::leader())
    std::ofstream(out + ".pools.csv")
        << pools_csv(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return 0;
}

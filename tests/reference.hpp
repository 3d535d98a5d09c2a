#pragma once
/// Reference results of the jobs users run, kept in versioned files as LAMMPS's unittest keeps each style's
/// (tests/reference/<case>.csv, docs/testing.md). A case is a function of the packing seed that returns its key
/// results; each file holds two kinds of row:
///   bits      the value at seed 1, to be reproduced exactly: the computation is deterministic (the same bits for
///             any thread count, and ctest runs every test at 1 and 2 threads), so any change shows;
///   scatterN  the mean over seeds 2 .. N+1 with a tolerance from their scatter, checked on seed 1, which is not
///             among them: a 99% prediction interval for one new specimen, t(0.995, N-1) s sqrt(1 + 1/N).
/// When a deliberate change moves the bits (another summation order, a new kernel), the bits rows are rewritten
/// and the scatter rows stay: the new code must still give, on a specimen it was not fitted to, what the old
/// code's population gave. Regenerating:
///   TRIAXDEM_WRITE_REFERENCE=bits build/tests/triaxdem_tests_fit --gtest_filter='Reference.*'   (bits rows only)
///   TRIAXDEM_WRITE_REFERENCE=all  build/tests/triaxdem_tests_fit --gtest_filter='Reference.*'   (also the scatter)
/// Without the variable a missing file, a missing or extra key, or a value beyond its tolerance fails the test,
/// naming the file and the key; nothing is ever rewritten then.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace dem::test {

/// Key results of a case, by file: {file stem -> {quantity -> value}}. One run may feed several files (the
/// membrane test's specimen, shear and micro measures).
using CaseResults = std::map<std::string, std::map<std::string, double>>;
using ReferenceCase = std::function<CaseResults(unsigned seed)>;

/// Seeds whose scatter sets the tolerance of the scatter rows (seed 1, the checked one, is not among them).
constexpr unsigned kScatterSeeds = 8;

namespace reference_detail {

struct Row {
  std::string quantity, basis;
  double value = 0, tolerance = 0;
};

inline std::string path_of(const std::string& stem) {
  return std::string(TRIAXDEM_SOURCE_DIR) + "/tests/reference/" + stem + ".csv";
}

/// Two-sided 99% quantile of Student's t with nu degrees of freedom (nu = N - 1 for the scatter seeds).
inline double t995(int nu) {
  static const double t[] = {0, 63.657, 9.925, 5.841, 4.604, 4.032, 3.707, 3.499, 3.355, 3.250, 3.169};
  return nu >= 1 && nu <= 10 ? t[nu] : 2.576 + 2.5 / nu;  // beyond 10: the normal's 2.576 plus its 1/nu term
}

inline std::vector<Row> read_rows(const std::string& path) {
  std::ifstream in(path);
  std::vector<Row> rows;
  if (!in) return rows;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty() || line[0] == '#' || line.rfind("quantity,", 0) == 0) continue;
    std::stringstream s(line);
    Row r;
    std::string value, tol;
    if (!std::getline(s, r.quantity, ',') || !std::getline(s, r.basis, ',') || !std::getline(s, value, ',') ||
        !std::getline(s, tol))
      throw std::runtime_error(path + ":" + std::to_string(n) + ": expected quantity,basis,value,tolerance");
    r.value = std::strtod(value.c_str(), nullptr);
    r.tolerance = std::strtod(tol.c_str(), nullptr);
    rows.push_back(r);
  }
  return rows;
}

inline void write_rows(const std::string& path, const std::string& stem, const std::vector<Row>& rows) {
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(tmp);
    out << "# triaxdem reference results: " << stem << " (tests/reference.hpp, docs/testing.md).\n"
        << "# bits: the value at packing seed 1, reproduced exactly. scatterN: the mean over seeds 2..N+1, and a 99%\n"
        << "# prediction interval for one more specimen, checked on seed 1.\n"
        << "# Regenerate: TRIAXDEM_WRITE_REFERENCE=bits|all build/tests/triaxdem_tests_fit --gtest_filter='Reference.*'\n"
        << "quantity,basis,value,tolerance\n";
    char buf[96];
    for (const Row& r : rows) {
      std::snprintf(buf, sizeof buf, "%.17g,%.6g", r.value, r.tolerance);
      out << r.quantity << "," << r.basis << "," << buf << "\n";
    }
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace reference_detail

/// Runs `run` at seed 1 and checks every file it feeds against tests/reference (see the top of the file);
/// `scatter` names, per file, the quantities that also get a scatter row (compared across specimens).
inline void check_reference(const ReferenceCase& run, const std::map<std::string, std::vector<std::string>>& scatter) {
  using namespace reference_detail;
  const char* env = std::getenv("TRIAXDEM_WRITE_REFERENCE");
  const std::string mode = env ? env : "";
  ASSERT_TRUE(mode.empty() || mode == "bits" || mode == "all")
      << "TRIAXDEM_WRITE_REFERENCE=" << mode << " (allowed: bits, all)";
  const CaseResults got = run(1);
  CaseResults sample_mean, sample_tol;
  if (mode == "all") {
    std::map<std::string, std::map<std::string, std::vector<double>>> sample;
    for (unsigned seed = 2; seed <= kScatterSeeds + 1; ++seed) {
      const CaseResults v = run(seed);
      for (const auto& [stem, keys] : scatter)
        for (const std::string& k : keys) sample[stem][k].push_back(v.at(stem).at(k));
    }
    for (const auto& [stem, keys] : sample)
      for (const auto& [k, xs] : keys) {
        const double n = static_cast<double>(xs.size());
        double m = 0, ss = 0;
        for (double x : xs) m += x / n;
        for (double x : xs) ss += (x - m) * (x - m);
        sample_mean[stem][k] = m;
        sample_tol[stem][k] = t995(static_cast<int>(n) - 1) * std::sqrt(ss / (n - 1)) * std::sqrt(1 + 1 / n);
      }
  }
  const std::string scatter_basis = "scatter" + std::to_string(kScatterSeeds);
  for (const auto& [stem, values] : got) {
    const std::string path = path_of(stem);
    if (!mode.empty()) {
      std::vector<Row> rows;
      for (const auto& [k, v] : values) rows.push_back({k, "bits", v, 0});
      if (mode == "all") {
        for (const std::string& k : scatter.count(stem) ? scatter.at(stem) : std::vector<std::string>{})
          rows.push_back({k, scatter_basis, sample_mean[stem][k], sample_tol[stem][k]});
      } else {
        for (const Row& r : read_rows(path))
          if (r.basis != "bits") rows.push_back(r);
      }
      write_rows(path, stem, rows);
      std::printf("reference: wrote %s (%s)\n", path.c_str(), mode.c_str());
    }
    const std::vector<Row> rows = read_rows(path);
    ASSERT_FALSE(rows.empty()) << path << ": missing or empty; make it with TRIAXDEM_WRITE_REFERENCE=all "
                               << "build/tests/triaxdem_tests_fit --gtest_filter='Reference.*' (docs/testing.md)";
    std::set<std::string> bits_keys, scatter_keys;
    for (const Row& r : rows) {
      if (r.basis == scatter_basis) scatter_keys.insert(r.quantity);
      const auto it = values.find(r.quantity);
      if (it == values.end()) {
        ADD_FAILURE() << path << ": key " << r.quantity << " (" << r.basis << ") is not a result of this case";
        continue;
      }
      if (r.basis == "bits") {
        bits_keys.insert(r.quantity);
        // Bitwise, as the deterministic computation promises (NaN equals NaN: a quantity the run cannot give).
        const bool same = it->second == r.value || (std::isnan(it->second) && std::isnan(r.value));
        EXPECT_TRUE(same) << path << ": " << r.quantity << " = " << std::setprecision(17) << it->second
                          << ", reference " << r.value << " (bits; if the change of bits is deliberate, regenerate "
                          << "with TRIAXDEM_WRITE_REFERENCE=bits and say why in the commit)";
      } else if (r.basis == scatter_basis) {
        EXPECT_LE(std::fabs(it->second - r.value), r.tolerance)
            << path << ": " << r.quantity << " = " << it->second << " on seed 1, the population of seeds 2-"
            << kScatterSeeds + 1 << " gives " << r.value << " +- " << r.tolerance << " (99% for a new specimen)";
      } else {
        ADD_FAILURE() << path << ": key " << r.quantity << ": basis '" << r.basis << "' (allowed: bits, "
                      << scatter_basis << ")";
      }
    }
    for (const auto& [k, v] : values)
      EXPECT_TRUE(bits_keys.count(k)) << path << ": key " << k << " has no reference row";
    for (const std::string& k : scatter.count(stem) ? scatter.at(stem) : std::vector<std::string>{})
      EXPECT_TRUE(scatter_keys.count(k)) << path << ": key " << k << " has no " << scatter_basis << " row";
  }
}

}  // namespace dem::test

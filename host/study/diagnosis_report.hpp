#pragma once
/// The diagnosis's report: diagnosis.md (the simulator, each material's finding and verdict, the models beside their
/// generic rivals, the reference values, the specimens' state and the gains) and models.csv. diagnose_job
/// (calibration_jobs.cpp) runs the diagnosis and prints its progress; this only writes what it found.
#include <sstream>
#include <string>
#include <vector>

#include "host/fit/diagnose.hpp"
#include "host/study/calibration_session.hpp"

namespace dem {

/// The names of the free parameters whose optimum lies at the edge of their search range, ", "-joined ("" where none).
std::string edge_names(const CalibrationResult& r);

class DiagnosisReport {
 public:
  /// The opening: the simulator, the free parameters, the misfit and noise, the reference values, the data's notes.
  DiagnosisReport(const Session& ss, const Config& base, const CalibrationOptions& o);
  /// A material's section. Returns the extension whose gains it shows: the one the verdict names, else the best by
  /// BIC (a candidate, to show what it would change); nullptr where the diagnosis fitted none.
  const ExtensionFit* add_material(const std::string& material, const std::vector<TriaxialTest>& tests,
                                   const Misfit& misfit, const Diagnosis& dg);
  /// The closing lines: the runs a blow-up stopped, the figure.
  void close();
  /// diagnosis.md, with `prediction` (the membrane test's section) after the report, and models.csv.
  void write(const std::string& prediction = "") const;

 private:
  void models_table(const std::string& material, const Diagnosis& dg, std::size_t tests);
  std::string reference_table(const std::string& material, const Diagnosis& dg) const;
  const Session& ss_;
  std::ostringstream md_, csv_;
};

}  // namespace dem

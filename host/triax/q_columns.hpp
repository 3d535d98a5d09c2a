#pragma once
/// The deviators a membrane test records beside its fixed-area q (docs/running.md, "Which q"): the lab measure each
/// is (none for the Love-Weber q, which no lab reports), its field in the records, its peak in a summary and its
/// column in series.csv. The one map from a measure to its fields: the fixed-area q, every other measure's default,
/// is the record's q, the summary's q_peak and the column q_kPa.
#include <optional>

#include "host/triax/summary.hpp"
#include "host/triax/triaxial.hpp"

namespace dem {

struct QColumn {
  std::optional<QMeasure> measure;
  Real TriaxialRecord::*record;
  Real TestSummary::*peak;
  const char* series_column;
};

inline const QColumn kQColumns[] = {
    {QMeasure::kAreaCorrected, &TriaxialRecord::q_area, &TestSummary::q_peak_area, "q_area_kPa"},
    {QMeasure::kParabolic, &TriaxialRecord::q_parabolic, &TestSummary::q_peak_parabolic, "q_parabolic_kPa"},
    {QMeasure::kMembraneCorrected, &TriaxialRecord::q_membrane, &TestSummary::q_peak_membrane, "q_membrane_kPa"},
    {std::nullopt, &TriaxialRecord::q_lw, &TestSummary::q_peak_lw, "q_lw_kPa"},
};

/// The column of measure `m`; none for the fixed-area q.
inline const QColumn* q_column(QMeasure m) {
  for (const QColumn& c : kQColumns)
    if (c.measure == m) return &c;
  return nullptr;
}

}  // namespace dem

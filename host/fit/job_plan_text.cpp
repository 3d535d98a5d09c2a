/// A job's plan as a whole: its totals and its text (the stages come from host/fit/job_plan.cpp).
#include <algorithm>
#include <cmath>

#include "host/fit/job_plan.hpp"
#include "host/util/progress.hpp"
#include "host/util/text_format.hpp"

namespace dem {

namespace {

std::string span(double low, double high) {
  return std::fabs(high - low) < 0.5 ? format_duration(high) : format_duration(low) + " to " + format_duration(high);
}

}  // namespace

double JobPlan::low() const {
  double s = 0;
  for (const PlanStage& p : stages) s += p.low;
  return s;
}

double JobPlan::high() const {
  double s = 0;
  for (const PlanStage& p : stages) s += p.high;
  return s;
}

double JobPlan::particle_steps() const {
  double s = 0;
  for (const PlanStage& p : stages) s += p.particle_steps;
  return s;
}

const PlanStage& JobPlan::costliest() const {
  return *std::max_element(stages.begin(), stages.end(),
                           [](const PlanStage& a, const PlanStage& b) { return a.high < b.high; });
}

std::string JobPlan::text(const std::string& kind) const {
  std::string s = kind + ": plan (before any packing):\n";
  for (const PlanStage& p : stages)
    s += "  " + p.name + ": " + p.work + fmt(", %.2g particle-steps, ", p.particle_steps) + span(p.low, p.high) + "\n";
  s += kind + ": in all " + fmt("%.2g particle-steps, ", particle_steps()) + "about " + span(low(), high()) +
       " on this machine\n";
  for (const std::string& n : notes) s += "  " + n + "\n";
  return s;
}

}  // namespace dem

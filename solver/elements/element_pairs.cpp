#include "solver/elements/element_pairs.hpp"

#include <cstdio>

namespace grip {

std::string element_pair_issue(const ContinuumOptions& options, const PlaneMaterial& law) {
  if (options.analysis == PlaneAnalysis::plane_stress) return {};
  const bool plain_q4 = options.element == ContinuumElement::q4 && options.incompressibility == Incompressibility::none;
  if (!plain_q4 && options.element != ContinuumElement::t3) return {};
  const std::string kind = options.element == ContinuumElement::t3 ? "t3" : "q4";
  std::string why;
  if (law.isochoric_flow()) {
    why = "plastic flow keeps the volume, and " + kind +
          " locks once the plastic zone spreads (limit loads come out too high, or never)";
  } else if (const double ratio = law.bulk_over_shear(); ratio > kLockingBulkOverShear) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.4g", ratio);
    why = "the law is nearly incompressible (bulk / shear modulus " + std::string(buf) + ", above " +
          std::to_string(static_cast<int>(kLockingBulkOverShear)) + "), and " + kind +
          " locks (too stiff by a factor that grows with that ratio)";
  } else {
    return {};
  }
  std::string instead;
  if (options.kinematics == ContinuumKinematics::finite)
    instead = "use q4 with \"incompressibility\": \"f_bar\", or t6 or q9 with \"mixed\" (or plain t6, q8, q9)";
  else if (options.analysis == PlaneAnalysis::axisymmetric) instead = "use t6, q8 or q9";
  else instead = "use q4_bbar (mean dilatation), t6, q8 or q9";
  return "\"" + kind + "\" is refused here: " + why + "; " + instead + " (docs/algorithm.md#element-formulation-pairs)";
}

}  // namespace grip

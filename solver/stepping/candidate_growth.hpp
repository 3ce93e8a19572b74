#pragma once
// Contact candidates that cannot be forgotten (docs/robustness.md#candidates): a boundary point
// outside the candidates that enters a rigid obstacle, or a site that comes within reach of an
// obstacle it was not paired with, becomes a candidate for the rest of the run. The contact
// unknowns of the new candidates come after the existing ones (before the rigid amplitudes), so
// what was solved so far keeps its values; the vectors made before are remapped with zeros for
// the new unknowns.
#include <string>
#include <vector>

#include "solver/stepping/step_checks.hpp"

namespace grip {

struct StepRecord;

struct CandidateGrowth {
  int old_first = 0;       // problem.rigid.first before
  int old_candidates = 0;  // problem.candidates.size() before
  int added_components = 0;
  std::string note;  // for the step's notes; empty if nothing was added
  bool grew() const { return added_components > 0; }
};

// Adds the candidates (a node without a site becomes a site first, where the body model can;
// else it is left out and named in the note).
CandidateGrowth add_candidates_for(Problem& problem, const std::vector<OutsidePoint>& outside);
// A vector of contact components made before the growth, in the new layout.
Vector grown_components(const Vector& v, const CandidateGrowth& g, const Problem& problem);
// A record made before the growth, in the new layout: its forces, bounds, s and pairing (the new
// candidates paired at the record's state, open).
void grow_record(StepRecord& rec, const CandidateGrowth& g, const Problem& problem);

}  // namespace grip

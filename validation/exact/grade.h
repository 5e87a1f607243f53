// Grading intersectors written in any language (`rayaudit audit --grade`):
// answers computed elsewhere for exported cases, booked exactly as a registered method.
//
// ANSWERS.csv: a header naming at least id,hit,t (u,v optional, other
// columns ignored), then one row per case of CASES.csv: hit is true/false
// (or 1/0), t a decimal or C99 hex float (empty when hit is false). Ids are
// those of the cases (the export's id column, or the row number when the
// cases have none). Export ids FAMILY:SWEEP:PROBE:K group the rows of one ray
// (edge pair, vertex fan, closed mesh) so leaks and double hits are judged
// per group; other ids are single cases of one family "cases".
#pragma once
#include <string>

#include "audit.h"

namespace ra::audit {

// Throws ra::InputError "FILE:LINE: what is wrong" (and reads everything
// before returning, so a caller writes nothing on bad input) for a
// malformed answer, a duplicate id, an id not in the cases, a case without
// an answer, a non-boolean hit or a hit without t. The report has one
// subject, "METHOD/PRECISION", and a cell per family and sweep value.
Report grade_answers(const std::string& answers_csv, const std::string& cases_csv, Precision p,
                     const std::string& method);

}  // namespace ra::audit

// The laboratory cases of validation.md part B at their scenario files' resolution, each printing
// its figures and, with check, the behaviour validation.md describes (returns 1 if one fails).
#pragma once

namespace runout::bench {

int lab_b1(bool check);
int lab_b2_inclined(bool check);  // 10, 20 and 30 deg
int lab_b3(bool check);
int lab_b4(bool check);
int lab_b5(bool check);
int lab_b7(bool full, bool check, int jobs);  // full: the scenario files' 2.5 mm; otherwise 5 mm; jobs: run_all's
int lab_b7_nest(bool check, int jobs);  // the cylinder at 5 mm: the whole chute against a nest on x >= 0.2 m
int lab_b8(bool check);
int lab_b10(bool check, int jobs);

}  // namespace runout::bench

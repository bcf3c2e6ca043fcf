/// \file The paper's statements, in its order: the first table of the reproduction report.
/// Each id is the `statement` of the checks that bear on it; a statement no check bears on is
/// reported as such (its derivation by hand is in docs/paper-derivations.md).

#include "amalgam/analysis/experiments.h"

namespace amalgam::experiments {

const std::vector<Statement>& statements() {
  static const std::vector<Statement> s = {
      {"Premise", "cost is the number of ray/object intersection tests", {"premise"}},
      {"Fig. 2: p vs P",
       "in Figure 2's scene p (primitives on the ray) varies as the square root of the number "
       "P of primitives",
       {"p-vs-P"}},
      {"C_t0",
       "worst-case traditional primary ray: sum_{i=0}^{l_max} n^i = O(p); shadow ray "
       "the same",
       {"worst-traditional", "worst-deterministic"}},
      {"Eq. 1",
       "C_s0 = sum_{i=0}^{l1} n^i = (n^{l1+1} - 1)/(n - 1) = O(n^{l1})",
       {"worst-deterministic"}},
      {"Eq. 2",
       "C_sd1 = n^{l1} C_s0 = O(n^{2 l1}) (one shadow ray per translucent amalgam)",
       {"worst-deterministic"}},
      {"2 l1 < l_max",
       "deterministic opacity beats the traditional renderer only while "
       "2 l1 < l_max",
       {"worst-deterministic"}},
      {"Efficient fraction",
       "alpha n^{l_max/2} / (alpha n^{l_max}) = alpha n^{-l_max/2} = "
       "alpha sqrt(1/p)",
       {"worst-deterministic"}},
      {"Eq. 3", "stochastic opacity: 2 C_s0 = O(n^{l1}), independent of p", {"worst-stochastic"}},
      {"More levels",
       "added levels below l1 leave the scale-sensitive time unchanged; the "
       "traditional renderer takes longer",
       {"more-levels"}},
      {"Sorting", "sorting children costs little (bucket sort, linear in n)", {"sorting"}},
      {"Eq. 4",
       "a traversal through i amalgams of level l1 costs at least l1 + i "
       "(objects traversed)",
       {"traversed"}},
      {"Eq. 5",
       "C_{l1} = sum_{i=0}^{l1} n^i ~ n b/(n - 1) objects above and within l1 (a count of the "
       "hierarchy: a traversal with nothing hit reaches them all)",
       {"traversed"}},
      {"Eq. 6", "C_b = C_{l1}/b ~ n/(n - 1), independent of l1", {"traversed"}},
      {"Eq. 7",
       "reaching the first i amalgams of l1 costs about i C_b, more accurately as i grows "
       "(objects traversed, and intersection tests for i >> n l1)",
       {"traversed"}},
      {"Eq. 8",
       "the cost of a traversal through i amalgams is max(log_n b + i, i C_b) "
       "(objects traversed)",
       {"traversed"}},
      {"Eq. 8, intersection tests",
       "Eq. 8 counted as this renderer's intersection tests (all n children of every "
       "entered node)",
       {"traversed"}},
      {"Eq. 9", "E[i] under the Poisson model (closed form)", {"expected"}},
      {"Eq. 10", "Eq. 9 with p/b = n (traditional renderer)", {"expected"}},
      {"Eq. 11", "a e^{-cp} + k -> k for large p", {}},
      {"Eq. 12", "the large-p limit of Eq. 10 is (1 - e^{-n}) = O(1)", {"expected"}},
      {"Eq. 13", "Eq. 9 with b fixed, O(1)", {"expected"}},
      {"O(log p) / O(log b)",
       "expected cost: O(log p) traditional, O(log b) scale-sensitive",
       {"expected"}},
      {"Secondary rays (expected)",
       "expected times for secondary rays have the same asymptotic behaviour",
       {"expected"}},
      {"Second Look sum",
       "failed tests: n^0 + sum_{i=1}^{l1} (n^{l1} + m n^{l1-1}) = "
       "1 + (1 + m/n) sum n^{l1} = O(n^{l1})",
       {"failed-tests"}},
      {"Failed tests (secondary, worst case)",
       "with failed tests, worst-case secondary rays also cost O(n^{l1}): the traditional "
       "and stochastic results stand",
       {"failed-tests"}},
      {"Failed tests (deterministic)",
       "the number of amalgams of l1 meeting the primary ray does not change, so the "
       "deterministic result stands",
       {"failed-tests"}},
      {"Failed tests (expected)",
       "failed tests scale the cost; the expected-case asymptotics stay valid",
       {"more-levels", "failed-tests"}},
      {"Lights", "cost scales with the number of lights", {"lights"}},
      {"FIND / PT2D / RAY2D",
       "FIND and PT2D on a tiling are O(log P); PT2D on overlaps and "
       "RAY2D are non-logarithmic",
       {"linear-cost"}},
      {"5D lazy evaluation",
       "Arvo and Kirk's lazily built 5D hierarchy embeds a sorting process, O(P log P), into "
       "the renderer, so it does not allow O(log P) performance",
       {}},
      {"Noise",
       "stochastic amalgams have lower image variance than the bounding volumes they "
       "replace, and stay cheaper after the extra sampling",
       {"noise", "noise-baked"}},
      {"No slower",
       "conclusions: in any case, the scale-sensitive technique is no slower (checked in "
       "tests and in wall time, repeated runs: slower where the time ratio's interval is "
       "above 1)",
       {"premise"}},
      {"Scanline", "scale-sensitive ray tracing beats scanline rendering, at best linear in p", {}},
  };
  return s;
}

const std::vector<PrintedSlip>& printed_slips() {
  static const std::vector<PrintedSlip> s = {
      {"Worst case, stochastic opacity (before Eq. 3)",
       "the shadow ray \"has the same, low cost as the primary ray (C_0)\"",
       "C_s0: the primary ray's cost through level l1 (Eq. 1); no C_0 is defined"},
      {"Expected case, scale-sensitive renderer (after Eq. 12)",
       "\"the time cost closely resembles Equations 3 and 12\"",
       "Equations 10 and 12: Eq. 3 is the worst-case stochastic total; the expected-case "
       "expressions with n for p/b are Eq. 10 and its limit, Eq. 12"},
      {"Abstract",
       "ray tracers with amalgams \"arguably have better asymptotic time complexity -- in both "
       "the best case and the expected case\"",
       "the body shows a better worst case (O(n^{l1}) against O(p)) and equal expected cases "
       "(O(log b) and O(log p) are the same order when l1 is a fixed number of levels above "
       "the bottom); the conclusions say so: \"Expected asymptotic costs ... are the same\", "
       "\"better worst case asymptotic costs\""},
  };
  return s;
}

}  // namespace amalgam::experiments

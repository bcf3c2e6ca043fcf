#pragma once
/// \file The cost formulas of Thompson & Fussell, "Time Costs of Ray Tracing with Amalgams",
/// TR-91-01, University of Texas at Austin, 1991 -- one function per equation.
///
/// Costs are numbers of intersection tests for one primary ray R_0 in the paper's stylized
/// uniform hierarchy (Figure 1): levels 0 (root) .. l_max (primitives), a ray that meets an
/// object meets n of its children, n^i objects on level i, p ~ n^{l_max} primitives on the ray.
///
/// Notation of the printed paper. Eqs. 9, 10, 12 and 13 write "(e^{p/b-1})" for (e^{p/b} - 1)
/// and "(e^{-p/b-1})" for (e^{-p/b} - 1) (likewise with n for p/b in Eqs. 10 and 12). This
/// reading is forced by the first line of the Eq. 9 derivation,
///   e^{-(p/b)(i-1)} (1 - e^{-p/b}) = (e^{p/b-1}) (e^{-p/b})^i,
/// which holds only if (e^{p/b-1}) = e^{p/b} - 1. The "_as_printed" functions transcribe the
/// printed expressions with that reading and nothing else changed.
///
/// Findings (derived by hand below, checked numerically in tests/analysis/formulas_test.cpp):
///  * C_t0, Eqs. 1, 2, 3, 5 and 6 are right.
///  * The efficient fraction is wrong as printed: alpha n^{l_max/2} / (alpha n^{l_max}) is
///    n^{-l_max/2} = sqrt(1/p), not alpha sqrt(1/p) (the alphas cancel; the printed form holds
///    for alpha = 1 only). Exactly, it is the ratio of two sums of the same kind,
///    (n^{l_max/2+1} - 1)/(n^{l_max+1} - 1) -> n^{-l_max/2}.
///  * "A Second Look" worst-case count: the printed summand n^{l_1} + m n^{l_1-1} is a typo
///    for n^i + m n^{i-1} (failed_tests_worst implements the corrected count).
///  * Eq. 9 (the printed closed form of E[i]) is algebraically exact: it equals
///    (1 - x^b)/(1 - x) with x = e^{-p/b}, the mean of the truncated geometric distribution.
///  * Eq. 10 is Eq. 9 with b = p/n, so it is exact too.
///  * Eq. 12 is wrong in its last step: its left side e^{-n}(e^n - 1)(e^{-n} - 1)^{-2} is
///    1/(1 - e^{-n}), but the paper prints "= (1 - e^{-n})" -- the reciprocal. E.g. n = 2:
///    correct 1.1565, printed 0.8647 (< 1, impossible for a count that is always >= 1).
///    The conclusion O(1) is unaffected.
///  * Eq. 13 (Eq. 9 rewritten with e^{p/b} e^{-p} = e^{-p(1-1/b)}) is algebraically exact; its
///    p -> infinity limit with b fixed is 1/(1 - e^{-p/b}) -> 1, i.e. O(1) as stated.
///
/// Argument errors (n < 1, negative levels, p < 0, b < 1, ...) throw InternalError (util/error.h);
/// the "_exact" integer variants throw std::overflow_error when the count exceeds uint64.

#include <cstdint>

namespace amalgam::formulas {

// ---------------------------------------------------------------------------------------------
// Worst case analysis
// ---------------------------------------------------------------------------------------------

/// Worst-case cost of a traditional primary ray (unnumbered equation before Eq. 1): the
/// number of objects in the whole hierarchy, C_t0 = sum_{i=0}^{l_max} n^i
/// = (n^{l_max+1} - 1)/(n - 1) = O(p). Valid for n >= 1 (n = 1 gives l_max + 1).
double c_t0(int n, int l_max);

/// C_t0 (before Eq. 1) as an exact integer.
std::uint64_t c_t0_exact(int n, int l_max);

/// Eq. 1: worst-case cost of a scale-sensitive primary ray that renders amalgams on level
/// l_1 and never traverses deeper: C_s0 = sum_{i=0}^{l_1} n^i = (n^{l_1+1} - 1)/(n - 1).
double c_s0(int n, int l1);

/// Eq. 1 (C_s0) as an exact integer.
std::uint64_t c_s0_exact(int n, int l1);

/// Eq. 2: worst-case cost of the shadow rays under deterministic opacity, one shadow ray of
/// cost C_s0 from each of the n^{l_1} translucent amalgams on level l_1:
/// C_sd1 = n^{l_1} C_s0 = (n^{2 l_1 + 1} - n^{l_1})/(n - 1) = O(n^{2 l_1}).
double c_sd1(int n, int l1);

/// Eq. 2 (C_sd1) as an exact integer.
std::uint64_t c_sd1_exact(int n, int l1);

/// Total worst-case cost with deterministic opacity (text after Eq. 2): C_s0 + C_sd1.
double deterministic_total(int n, int l1);

/// Eq. 3: total worst-case cost with stochastic opacity -- the primary ray plus at most one
/// shadow ray of the same cost: 2 C_s0 = O(n^{l_1}), independent of p.
double stochastic_total(int n, int l1);

/// Eq. 3 (2 C_s0) as an exact integer.
std::uint64_t stochastic_total_exact(int n, int l1);

/// The "efficient" fraction of the database (unnumbered, after Eq. 2): with l_1 = l_max/2 the
/// efficiently renderable part holds alpha n^{l_max/2} of alpha n^{l_max} objects, i.e. the
/// fraction n^{-l_max/2} = sqrt(1/p) for p = n^{l_max} (the alphas cancel). Requires p > 0.
double efficient_fraction(double p);

/// The fraction as printed, alpha sqrt(1/p): wrong unless alpha = 1. Requires p > 0.
double efficient_fraction_as_printed(double alpha, double p);

/// The fraction exactly, as the ratio of the counts it stands for: C_s0 at l1 = l_max/2 (l_max
/// even) over C_t0, (n^{l_max/2+1} - 1)/(n^{l_max+1} - 1) (n >= 2, l_max >= 0 even).
double efficient_fraction_exact(int n, int l_max);

// ---------------------------------------------------------------------------------------------
// "A Second Look": failed intersection tests
// ---------------------------------------------------------------------------------------------

/// Worst-case number of objects examined through level l_1 when every traversed amalgam also
/// holds m "failed" children (unnumbered equation in "A Second Look"):
///   n^0 + sum_{i=1}^{l_1} (n^i + m n^{i-1}) = 1 + (1 + m/n) sum_{i=1}^{l_1} n^i = O(n^{l_1}).
/// The paper prints the summand as n^{l_1} + m n^{l_1-1}, which does not depend on the
/// summation index -- a typo: the text states there are m n^{l_i - 1} extra amalgams on each
/// level l_i. This function implements the corrected per-level count n^i + m n^{i-1}.
/// With m = 0 it reduces to C_s0 (Eq. 1).
double failed_tests_worst(int n, int m, int l1);

/// failed_tests_worst as an exact integer.
std::uint64_t failed_tests_worst_exact(int n, int m, int l1);

/// The "A Second Look" sum evaluated literally as printed (typo included):
/// 1 + sum_{i=1}^{l_1} (n^{l_1} + m n^{l_1-1}) = 1 + l_1 (n^{l_1} + m n^{l_1-1}).
/// Agrees with failed_tests_worst only for l_1 <= 1; it is O(l_1 n^{l_1}), not O(n^{l_1}).
double failed_tests_worst_as_printed(int n, int m, int l1);

// ---------------------------------------------------------------------------------------------
// Expected case analysis: cost of a traversal through i amalgams on level l_1
// ---------------------------------------------------------------------------------------------

/// Eq. 4: lower bound on the cost of a sorted traversal that stops after the i-th of the
/// b = n^{l_1} bounding volumes on level l_1: the l_1 = log_n b objects of the "left edge"
/// plus the i objects on level l_1, i.e. log_n(b) + i. Requires n >= 2, b >= 1.
double eq4_lower_bound(int n, double b, double i);

/// Eq. 5: total number of objects (traversed or not) above and within level l_1,
/// C_{l_1} = sum_{i=0}^{l_1} n^i = (n^{l_1+1} - 1)/(n - 1) (the exact sum; same as C_s0).
double c_l1(int n, int l1);

/// Eq. 5, the approximation C_{l_1} ~ n^{l_1+1}/(n - 1) = n b/(n - 1). Requires n >= 2.
double c_l1_approx(int n, double b);

/// Eq. 6: average cost of reaching one of the b amalgams on level l_1,
/// C_b ~ (1/b)(n b/(n - 1)) = n/(n - 1), independent of l_1. Requires n >= 2.
double c_b(int n);

/// Eq. 6 without the approximation of Eq. 5: C_{l_1}/b = (n^{l_1+1} - 1)/((n - 1) n^{l_1})
/// = n/(n - 1) - 1/((n - 1) n^{l_1}); tends to c_b(n) as l_1 grows. Requires n >= 2.
double c_b_exact(int n, int l1);

/// Eq. 7: the estimate i C_b of the cost of reaching the first i objects on level l_1
/// (accurate for large i). Requires n >= 2.
double eq7_linear_cost(int n, double i);

/// The exact cost, in objects traversed (Figure 4's counting: the root, each node reached in
/// sorted order, the amalgams reached on level l_1), of a sorted traversal that stops at the
/// i-th of the b = n^{l_1} amalgams on level l_1 when every amalgam lies on the ray:
/// sum_{k=0}^{l_1} ceil(i / n^{l_1 - k}) (the level-k ancestors of the first i amalgams).
/// It lies between i C_{l_1}/b and i C_{l_1}/b + l_1 + 1 (each ceiling adds less than one),
/// so Eq. 7's i C_b is off by less than (l_1 + 1)/(i C_b) relatively: accurate for i >> l_1.
/// i = 1 gives l_1 + 1 (Eq. 4, attained); i = b gives C_{l_1} (Eq. 5). Requires n >= 2,
/// 1 <= i <= n^{l_1}.
double objects_traversed_to(int n, int l1, double i);

/// The same traversal counted as this renderer's intersection tests: the root's box, then
/// all n children of every entered node, 1 + n sum_{k=0}^{l_1-1} ceil(i / n^{l_1 - k}).
/// Within n l_1 + 1 of i C_{l_1}/b, so Eq. 7 holds for i >> n l_1 under this counting too;
/// i = 1 gives 1 + n l_1, n times Eq. 4's l_1 + 1 for large l_1. Requires n >= 2,
/// 1 <= i <= n^{l_1}.
double tests_to(int n, int l1, double i);

/// Eq. 8: the paper's overall cost of a traversal through i amalgams on level l_1,
/// max(log_n b + i, i C_b) with C_b = n/(n - 1) from Eq. 6. Requires n >= 2, b >= 1.
double eq8_cost(int n, double b, double i);

// ---------------------------------------------------------------------------------------------
// Expected case analysis: the expected number of amalgams visited on level l_1 (Eqs. 9-13)
// ---------------------------------------------------------------------------------------------
//
// Model (Poisson intersections): each of the b amalgams on level l_1 independently stops the
// ray (a primitive inside is hit / the amalgam is stochastically opaque) with probability
// 1 - x, x = e^{-p/b}; they are visited nearest first. The number i of amalgams visited is a
// geometric variable truncated at b:
//   P(i) = x^{i-1} (1 - x)  for 1 <= i < b,   P(b) = x^{b-1}  (= 1 - sum_{i<b} P(i)).
// Its mean is E[i] = sum_{k=1}^{b} P(i >= k) = sum_{k=1}^{b} x^{k-1} = (1 - x^b)/(1 - x)
// = expm1(-p)/expm1(-p/b) (using x^b = e^{-p}); E[i] = b when p = 0, and 1 <= E[i] <= b.

/// The truncated-geometric probability of Eq. 9's derivation that exactly the first i of the
/// b amalgams on level l_1 are visited: x^{i-1}(1 - x) for i < b, x^{b-1} for i = b, 0
/// otherwise (x = e^{-p/b}). The paper writes the i < b case as (e^{p/b} - 1)(e^{-p/b})^i,
/// which is the same number. Requires p >= 0, b >= 1, 1 <= i (returns 0 for i > b).
double visit_probability(std::uint64_t i, double p, std::uint64_t b);

/// The i < b probability of Eq. 9's derivation evaluated as printed,
/// (e^{p/b} - 1)(e^{-p/b})^i. Correct: equals visit_probability(i, p, b) for 1 <= i < b.
double visit_probability_as_printed(std::uint64_t i, double p, double b);

/// The exact expected number of amalgams visited on level l_1 (the quantity of Eq. 9), by
/// the closed form of the truncated geometric mean, E[i] = (1 - x^b)/(1 - x)
/// = expm1(-p)/expm1(-p/b), accurate for tiny and huge p/b alike. b may be non-integral
/// (the formula is then the analytic continuation). Requires p >= 0, b >= 1.
double expected_visits_exact(double p, double b);

/// The same expectation by the direct sum sum_{i=1}^{b} i P(i) over the distribution
/// (O(b) work; a reference for expected_visits_exact). Requires p >= 0, b >= 1.
double expected_visits_sum(double p, std::uint64_t b);

/// Eq. 9 as printed (its final closed form), with x = e^{-p/b}:
///   (e^{p/b} - 1)(e^{-p/b} - 1)^{-2} [ (b e^{-p/b} - e^{-p/b} - b) e^{-p} + e^{-p/b} ]
///   - b (e^{p/b} - 1)(e^{-p/b} - 1)^{-1} e^{-p}.
/// Evaluated term by term exactly as printed (in long double, with expm1 for the (e^{.} - 1)
/// factors). Hand check: (e^{p/b} - 1)/(x - 1)^2 = 1/(x(1 - x)) and
/// (e^{p/b} - 1)/(x - 1) = -1/x, so the expression is
///   [(b x - x - b) x^{b-1} + 1]/(1 - x) + b x^{b-1} = (1 - x^b)/(1 - x),
/// i.e. Eq. 9 is CORRECT (equal to expected_visits_exact). The intermediate steps of its
/// derivation (the two sum identities, the b-terms cancelling) are also correct.
/// Numerically it cancels badly for p/b << 1 (bracket ~ (p/b)^2) and overflows once
/// e^{p/b} exceeds the long double range; use expected_visits_exact for real work.
/// Requires p > 0, b >= 1.
double expected_visits_eq9_as_printed(double p, double b);

/// Eq. 10 as printed: Eq. 9 for the traditional renderer (l_1 = l_max - 1, p/b = n,
/// b = p/n):
///   (e^n - 1)(e^{-n} - 1)^{-2} [ ((p/n) e^{-n} - e^{-n} - p/n) e^{-p} + e^{-n} ]
///   - (p/n)(e^n - 1)(e^{-n} - 1)^{-1} e^{-p}.
/// CORRECT: a faithful substitution into Eq. 9, equal to expected_visits_exact(p, p/n)
/// = (1 - e^{-p})/(1 - e^{-n}). Requires n >= 1, p > 0.
double eq10_traditional(int n, double p);

/// Eq. 12 as printed: the claimed large-p limit of Eq. 10, (1 - e^{-n}).
/// WRONG: the left side of Eq. 12 is 1/(1 - e^{-n}) (see eq12_lhs_as_printed); the printed
/// right side is its reciprocal. Since at least one amalgam is always visited the expected
/// count is >= 1, while 1 - e^{-n} < 1. (Both are O(1), so the paper's conclusion stands.)
double eq12_limit(int n);

/// The left side of Eq. 12 as printed, e^{-n}(e^n - 1)(e^{-n} - 1)^{-2}: what remains of
/// Eq. 10 after dropping the e^{-p} terms by Eq. 11. Equals 1/(1 - e^{-n}) (correct).
double eq12_lhs_as_printed(int n);

/// The true large-p limit of the expected number of amalgams visited on level l_max - 1 with
/// p/b = n: lim_{p->inf} (1 - e^{-p})/(1 - e^{-n}) = 1/(1 - e^{-n}) = -1/expm1(-n).
double eq12_correct_limit(int n);

/// Eq. 13 as printed: Eq. 9 for the scale-sensitive renderer with b independent of p,
/// rewritten with e^{p/b} e^{-p} = e^{-p(1-1/b)}:
///   (e^{-p(1-1/b)} - e^{-p})(e^{-p/b} - 1)^{-2}(b e^{-p/b} - e^{-p/b} - b)
///   - (e^{-p/b} - 1)^{-1} - b (e^{-p(1-1/b)} - e^{-p})(e^{-p/b} - 1)^{-1}.
/// CORRECT: (e^{p/b} - 1) e^{-p} = e^{-p(1-1/b)} - e^{-p} and (e^{p/b} - 1)(x - 1)^{-2} x =
/// -(x - 1)^{-1}, so this is Eq. 9 term for term and equals expected_visits_exact(p, b).
/// For fixed b > 1 and p -> infinity it tends to 1/(1 - e^{-p/b}) -> 1 = O(1), as stated.
/// Requires p > 0, b >= 1.
double eq13_scale_sensitive(double p, double b);

/// The exact expectation of Eq. 8's cost model under Eq. 9's distribution,
/// E[max(log_n b + i, i C_b)] = sum_i P(i) max(log_n b + i, i n/(n - 1)). Uses the direct
/// sum only while the first branch of the max wins (i <= (n - 1) log_n b) and E[i] for the
/// linear tail, so it costs O(n log b). Requires n >= 2, p >= 0, b >= 1.
double expected_eq8_cost(int n, std::uint64_t b, double p);

// ---------------------------------------------------------------------------------------------
// Exact expected test counts of explicit traversals of the uniform hierarchy
// ---------------------------------------------------------------------------------------------

/// Exact expected number of intersection tests for a primary ray in the uniform n-ary
/// hierarchy cut at level l_1 (scale-sensitive renderer, stochastic opacity):
///  * the root (level 0) is tested once and always entered;
///  * entering a node on level k < l_1 tests ALL its n children (n tests), then processes
///    them nearest first: a child on a level < l_1 is entered recursively; a child on level
///    l_1 (a rendered amalgam, b = n^{l_1} of them) costs no further test and independently
///    "hits" with probability q = 1 - e^{-p/b};
///  * the whole traversal stops at the first hit.
/// Derivation. A subtree rooted on level k holds n^{l_1-k} level-l_1 nodes, so it produces no
/// hit with probability s_k = (1 - q)^{n^{l_1-k}} = e^{-mu_k}, mu_k = p/n^k. Let t_k be the
/// expected number of tests made inside an entered level-k node (excluding its own test).
/// Its j-th child (j = 1..n) is processed iff the j - 1 earlier siblings produced no hit
/// (probability s_{k+1}^{j-1}), and, subtrees being independent, the cost of processing it is
/// independent of that event, so
///   t_{l_1} = 0,   t_k = n + t_{k+1} G(n, mu_{k+1}),   G(n, mu) = sum_{j=0}^{n-1} e^{-j mu}
///   = expm1(-n mu)/expm1(-mu)  (G = n for mu = 0),
/// and the answer is 1 + t_0 = 1 + n sum_{k=0}^{l_1-1} prod_{j=1}^{k} G(n, p/n^j).
/// Checks: p = 0 gives 1 + n + ... + n^{l_1} = C_s0 (Eq. 1, the worst case); p -> infinity
/// gives 1 + n l_1 (only the left edge is entered, all n children tested per level). The
/// number of level-l_1 nodes processed follows exactly Eq. 9's distribution.
/// With m failed objects per node ("A Second Look": tested, never hit, never entered) every
/// entered node costs n + m tests instead of n. Requires n >= 1, l_1 >= 0, p >= 0, m >= 0.
double expected_tests_sorted(int n, int l1, double p, int m = 0);

/// As expected_tests_sorted, but a child is tested only when the traversal reaches it
/// (tested, then -- if above l_1 -- entered before the next sibling is tested); this is the
/// counting of the paper's Figure 4/Eq. 4 (left edge + interior + the i on level l_1).
/// Recursion: t_{l_1} = 0, t_k = G(n, mu_{k+1}) (1 + t_{k+1}); answer 1 + t_0.
/// p = 0 gives C_s0; p -> infinity gives 1 + l_1 = eq4_lower_bound(n, n^{l_1}, 1).
/// Requires n >= 1, l_1 >= 0, p >= 0.
double expected_tests_sorted_lazy(int n, int l1, double p);

/// Exact expected number of intersection tests for the traditional renderer on the same
/// hierarchy down to the primitives on level l_max: nodes on levels < l_max - 1 are entered as
/// in expected_tests_sorted (all n children tested, nearest first); entering a bottom node
/// (level l_max - 1) tests all its n primitives (n tests), each hit independently with
/// probability q = 1 - e^{-p/n^{l_max}}, and the ray stops if any was hit.
/// Derivation: t_{l_max-1} = n, and for k < l_max - 1 the recursion of expected_tests_sorted
/// with mu_{k+1} = p/n^{k+1}; a bottom node produces no hit with probability
/// (1 - q)^n = e^{-p/n^{l_max-1}}. This coincides with expected_tests_sorted(n, l_max, p):
/// the primitives play the role of level-l_1 units that cost nothing beyond the parent's n
/// tests. p = 0 gives C_t0. With m failed objects per node every entered node (a bottom one
/// too) costs n + m tests. Requires n >= 1, l_max >= 1, p >= 0, m >= 0.
double expected_tests_traditional(int n, int l_max, double p, int m = 0);

}  // namespace amalgam::formulas

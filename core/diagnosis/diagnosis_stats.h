// Statistics of the gap diagnosis (core/diagnosis/diagnosis.h): the paired test that
// decides whether an effect's held-out improvement is consistent across
// days, the partial correlation that is an effect's residual evidence, the
// noise floor of a residual series, and the Student t distribution they
// need. Pure functions, no state.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pvtwin {

// One-sided paired comparison of `before` and `after` (one value per unit,
// e.g. the held-out MAE of each day), H1: after < before.
//
// Differences d_i = before_i − after_i; pairs with d_i = 0 are dropped
// (Wilcoxon's convention), the rest ranked by |d_i| with mid-ranks for ties.
//  * Wilcoxon signed-rank: W+ = Σ rank_i over d_i > 0; p = P(W+ ≥ observed)
//    under H0 (each sign ±1 with probability ½), exact by counting the 2^n
//    sign patterns over doubled ranks (integers also with mid-ranks) for
//    n ≤ kExactWilcoxonMaxN, else the normal approximation with continuity
//    and tie correction.
//  * Sign test: p = P(Bin(n, ½) ≥ positives).
//  * Paired t: t = mean(d) / (sd(d)/√n), p = P(T_{n−1} ≥ t) over all pairs
//    (zeros included); 1 when n < 2 or sd = 0 with mean ≤ 0 (0 when sd = 0 and
//    mean > 0).
struct PairedTest {
  std::size_t pairs = 0;      // all pairs
  std::size_t nonzero = 0;    // n of the rank tests
  std::size_t positives = 0;  // pairs where after < before
  double w_plus = 0.0;        // Wilcoxon W+ (sum of ranks of positive d)
  double wilcoxon_p = 1.0;
  double sign_p = 1.0;
  double t_stat = 0.0;
  double t_p = 1.0;
  double mean_difference = 0.0;  // mean(before − after)
};

inline constexpr std::size_t kExactWilcoxonMaxN = 200;

PairedTest OneSidedPairedTest(std::span<const double> before, std::span<const double> after);

// One-sided test of equal predictive accuracy on per-row losses (Diebold &
// Mariano 1995, "Comparing predictive accuracy", J. Bus. Econ. Stat. 13,
// 253–263), H1: `after` has the smaller expected loss.
//
// d_j = before_j − after_j over the rows where both are finite (j in row
// order); the variance of mean(d) is the heteroscedasticity- and
// autocorrelation-consistent (Newey–West) estimate with Bartlett weights
// w_k = 1 − k/(L+1), k = 1 … L rows, L = bandwidth_s / median row step, and
// a lag pair (j, j+k) only counted when the two rows lie within bandwidth_s
// of each other (no pair across a night's gap):
//   var = (γ_0 + 2·Σ_k w_k·γ_k) / n,  γ_k = Σ_j d̃_j·d̃_{j+k} / n,
// floored at γ_0 / n / (L+1) (the estimate can turn negative when pairs are
// dropped). z = mean(d)/√var, p = 1 − Φ(z). Unlike a rank test over a few
// days, p does not saturate: 7 of 7 units give a Wilcoxon p of 0.0078 at
// best, while here a consistent improvement over many hours gives a small p
// and an effect that acts on only some days still counts where it acts.
// rows < 3 or var = 0 give p = 1 (0 when var = 0 and mean > 0).
struct LossDifferenceTest {
  std::size_t rows = 0;
  int bandwidth_rows = 0;        // L
  double mean_difference = 0.0;  // mean(before − after)
  double std_error = 0.0;        // √var
  double z = 0.0;
  double p = 1.0;
};

LossDifferenceTest OneSidedLossDifferenceTest(std::span<const double> before,
                                              std::span<const double> after,
                                              std::span<const std::int64_t> time_s,
                                              double bandwidth_s);

// P(T_ν ≤ t) of Student's t distribution with ν > 0 degrees of freedom, from
// the regularised incomplete beta function (continued fraction, Numerical
// Recipes §6.4): P(T ≤ t) = 1 − ½·I_{ν/(ν+t²)}(ν/2, ½) for t ≥ 0.
double StudentTCdf(double t, double dof);

// I_x(a, b), the regularised incomplete beta function, a, b > 0, x in [0, 1].
double RegularisedIncompleteBeta(double x, double a, double b);

// Partial correlation of y and x after removing from each the least-squares
// fit on [1, controls...] over the rows where y, x and every control are
// finite. n_eff corrects the sample size for autocorrelation (Bartlett):
// n_eff = n·(1 − ρ_y·ρ_x)/(1 + ρ_y·ρ_x) with ρ the lag-1 autocorrelations of
// the two adjusted series, clamped to [3, n]; z = r·√(n_eff − 2)/√(1 − r²)
// (≈ normal for large n_eff). rows = 0 or a constant adjusted series give
// r = z = 0.
struct PartialCorrelation {
  std::size_t rows = 0;
  double r = 0.0;
  double n_eff = 0.0;
  double z = 0.0;
};

PartialCorrelation PartialCorrelate(std::span<const double> y, std::span<const double> x,
                                    const std::vector<std::vector<double>>& controls);

// Mean absolute sensor noise of a residual (or measurement) series estimated
// from its second differences e_i = r_{i+1} − 2·r_i + r_{i−1}, taken only where
// rows i−1, i, i+1 are consecutive (segment[i] equal and present). For white
// noise of standard deviation σ_i that changes slowly, e_i has variance 6σ_i²,
// so mean|e|/√6 estimates mean σ_i·√(2/π), the MAE that the noise alone gives
// a perfect model; smooth model error (anything linear over three rows)
// cancels. The largest `trim` fraction of |e| (spikes, cloud edges) is
// dropped and the mean of the rest rescaled by the half-normal's trimmed mean
// so that pure Gaussian noise is still estimated without bias. Returns NaN
// when fewer than 10 triples exist.
double NoiseMaeFromSecondDifferences(std::span<const double> r,
                                     std::span<const std::int64_t> segment, double trim = 0.05);

}  // namespace pvtwin

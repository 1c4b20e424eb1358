#include "core/diagnosis/diagnosis_stats.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>

namespace pvtwin {

namespace {

// Log of the beta function via lgamma.
double LogBeta(double a, double b) { return std::lgamma(a) + std::lgamma(b) - std::lgamma(a + b); }

// Continued fraction of the incomplete beta function (Lentz's method,
// Numerical Recipes §6.4, betacf).
double BetaContinuedFraction(double x, double a, double b) {
  constexpr int kMaxIterations = 300;
  constexpr double kEps = 1e-15;
  constexpr double kTiny = 1e-300;
  const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
  double c = 1.0;
  double d = 1.0 - qab * x / qap;
  if (std::fabs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= kMaxIterations; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1.0 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1.0 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::fabs(del - 1.0) < kEps) break;
  }
  return h;
}

// P(Bin(n, ½) ≥ k).
double BinomialUpperTail(std::size_t n, std::size_t k) {
  if (k == 0) return 1.0;
  if (k > n) return 0.0;
  double sum = 0.0;
  for (std::size_t j = k; j <= n; ++j) {
    sum += std::exp(std::lgamma(n + 1.0) - std::lgamma(j + 1.0) - std::lgamma(n - j + 1.0) -
                    static_cast<double>(n) * std::log(2.0));
  }
  return std::min(1.0, sum);
}

// Lag-1 autocorrelation of x (mean removed).
double Lag1Autocorrelation(const Eigen::VectorXd& x) {
  const double mean = x.mean();
  double num = 0.0, den = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    den += (x[i] - mean) * (x[i] - mean);
    if (i > 0) num += (x[i] - mean) * (x[i - 1] - mean);
  }
  return den > 0.0 ? num / den : 0.0;
}

// Standard normal upper quantile by bisection on erfc: z with P(|Z| > z) = tail.
double TwoSidedNormalQuantile(double tail) {
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (std::erfc(mid / std::sqrt(2.0)) > tail) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

}  // namespace

double RegularisedIncompleteBeta(double x, double a, double b) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  const double front = std::exp(a * std::log(x) + b * std::log1p(-x) - LogBeta(a, b));
  if (x < (a + 1.0) / (a + b + 2.0)) return front * BetaContinuedFraction(x, a, b) / a;
  return 1.0 - front * BetaContinuedFraction(1.0 - x, b, a) / b;
}

double StudentTCdf(double t, double dof) {
  if (std::isnan(t) || !(dof > 0.0)) return std::nan("");
  if (std::isinf(t)) return t > 0 ? 1.0 : 0.0;
  const double tail = 0.5 * RegularisedIncompleteBeta(dof / (dof + t * t), 0.5 * dof, 0.5);
  return t >= 0.0 ? 1.0 - tail : tail;
}

PairedTest OneSidedPairedTest(std::span<const double> before, std::span<const double> after) {
  PairedTest test;
  const std::size_t n = std::min(before.size(), after.size());
  test.pairs = n;
  std::vector<double> d(n);
  for (std::size_t i = 0; i < n; ++i) d[i] = before[i] - after[i];

  // Paired t over all pairs.
  if (n > 0) {
    const double mean = std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(n);
    test.mean_difference = mean;
    if (n >= 2) {
      double ss = 0.0;
      for (double x : d) ss += (x - mean) * (x - mean);
      const double sd = std::sqrt(ss / static_cast<double>(n - 1));
      if (sd > 0.0) {
        test.t_stat = mean / (sd / std::sqrt(static_cast<double>(n)));
        test.t_p = 1.0 - StudentTCdf(test.t_stat, static_cast<double>(n - 1));
      } else {
        test.t_stat = mean > 0.0 ? INFINITY : 0.0;
        test.t_p = mean > 0.0 ? 0.0 : 1.0;
      }
    }
  }

  // Rank tests over the non-zero differences.
  std::vector<double> nz;
  for (double x : d) {
    if (x != 0.0 && std::isfinite(x)) nz.push_back(x);
  }
  const std::size_t m = nz.size();
  test.nonzero = m;
  if (m == 0) return test;
  std::vector<std::size_t> order(m);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&nz](std::size_t a, std::size_t b) { return std::fabs(nz[a]) < std::fabs(nz[b]); });
  // Doubled mid-ranks: ties at 1-based positions i..j get rank (i + j)/2,
  // doubled: i + j (an integer).
  std::vector<int> rank2(m);
  double tie_correction = 0.0;  // Σ (t³ − t) over tie groups
  for (std::size_t i = 0; i < m;) {
    std::size_t j = i;
    while (j + 1 < m && std::fabs(nz[order[j + 1]]) == std::fabs(nz[order[i]])) ++j;
    const int r2 = static_cast<int>((i + 1) + (j + 1));
    for (std::size_t k = i; k <= j; ++k) rank2[order[k]] = r2;
    const double t = static_cast<double>(j - i + 1);
    tie_correction += t * t * t - t;
    i = j + 1;
  }
  int w2 = 0;  // doubled W+
  for (std::size_t i = 0; i < m; ++i) {
    if (nz[i] > 0.0) {
      w2 += rank2[i];
      ++test.positives;
    }
  }
  test.w_plus = 0.5 * w2;
  test.sign_p = BinomialUpperTail(m, test.positives);

  if (m <= kExactWilcoxonMaxN) {
    // counts[s] = number of sign patterns with doubled W+ = s, in units of
    // 2^-m (probabilities, to stay finite for large m).
    const int total2 = std::accumulate(rank2.begin(), rank2.end(), 0);
    std::vector<double> prob(static_cast<std::size_t>(total2) + 1, 0.0);
    prob[0] = 1.0;
    int reach = 0;
    for (std::size_t i = 0; i < m; ++i) {
      const int r = rank2[i];
      for (int s = reach; s >= 0; --s) {
        const double p = prob[static_cast<std::size_t>(s)];
        prob[static_cast<std::size_t>(s)] = 0.5 * p;
        prob[static_cast<std::size_t>(s + r)] += 0.5 * p;
      }
      reach += r;
    }
    double tail = 0.0;
    for (int s = w2; s <= total2; ++s) tail += prob[static_cast<std::size_t>(s)];
    test.wilcoxon_p = std::min(1.0, tail);
  } else {
    const double md = static_cast<double>(m);
    const double mean = md * (md + 1.0) / 4.0;
    const double var = md * (md + 1.0) * (2.0 * md + 1.0) / 24.0 - tie_correction / 48.0;
    const double z = (test.w_plus - mean - 0.5) / std::sqrt(var);
    test.wilcoxon_p = 0.5 * std::erfc(z / std::sqrt(2.0));
  }
  return test;
}

LossDifferenceTest OneSidedLossDifferenceTest(std::span<const double> before,
                                              std::span<const double> after,
                                              std::span<const std::int64_t> time_s,
                                              double bandwidth_s) {
  LossDifferenceTest out;
  std::vector<double> d;
  std::vector<std::int64_t> t;
  for (std::size_t i = 0; i < before.size() && i < after.size() && i < time_s.size(); ++i) {
    if (!std::isfinite(before[i]) || !std::isfinite(after[i])) continue;
    d.push_back(before[i] - after[i]);
    t.push_back(time_s[i]);
  }
  const std::size_t n = d.size();
  out.rows = n;
  if (n < 3) return out;
  std::vector<std::int64_t> steps;
  for (std::size_t j = 1; j < n; ++j) {
    if (t[j] > t[j - 1]) steps.push_back(t[j] - t[j - 1]);
  }
  std::int64_t step = 60;
  if (!steps.empty()) {
    std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
    step = std::max<std::int64_t>(1, steps[steps.size() / 2]);
  }
  const int lags = std::max(0, static_cast<int>(bandwidth_s / static_cast<double>(step)));
  out.bandwidth_rows = lags;
  const double mean = std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(n);
  out.mean_difference = mean;
  for (double& x : d) x -= mean;
  double gamma0 = 0.0;
  for (const double x : d) gamma0 += x * x;
  gamma0 /= static_cast<double>(n);
  double sum = gamma0;
  for (int k = 1; k <= lags; ++k) {
    double gk = 0.0;
    for (std::size_t j = 0; j + static_cast<std::size_t>(k) < n; ++j) {
      const std::size_t m = j + static_cast<std::size_t>(k);
      if (static_cast<double>(t[m] - t[j]) <= bandwidth_s) gk += d[j] * d[m];
    }
    sum += 2.0 * (1.0 - k / (lags + 1.0)) * gk / static_cast<double>(n);
  }
  const double var = std::max(sum, gamma0 / (lags + 1.0)) / static_cast<double>(n);
  if (!(var > 0.0)) {
    out.p = mean > 0.0 ? 0.0 : 1.0;
    return out;
  }
  out.std_error = std::sqrt(var);
  out.z = mean / out.std_error;
  out.p = 0.5 * std::erfc(out.z / std::sqrt(2.0));
  return out;
}

PartialCorrelation PartialCorrelate(std::span<const double> y, std::span<const double> x,
                                    const std::vector<std::vector<double>>& controls) {
  PartialCorrelation out;
  const std::size_t n = std::min(y.size(), x.size());
  std::vector<std::size_t> rows;
  rows.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    bool ok = std::isfinite(y[i]) && std::isfinite(x[i]);
    for (const std::vector<double>& c : controls) ok = ok && i < c.size() && std::isfinite(c[i]);
    if (ok) rows.push_back(i);
  }
  const Eigen::Index k = static_cast<Eigen::Index>(controls.size()) + 1;
  if (rows.size() < static_cast<std::size_t>(k) + 3) return out;
  const Eigen::Index m = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd a(m, k);
  Eigen::VectorXd vy(m), vx(m);
  for (Eigen::Index r = 0; r < m; ++r) {
    const std::size_t i = rows[static_cast<std::size_t>(r)];
    a(r, 0) = 1.0;
    for (Eigen::Index c = 1; c < k; ++c) a(r, c) = controls[static_cast<std::size_t>(c - 1)][i];
    vy[r] = y[i];
    vx[r] = x[i];
  }
  // Scale columns so that the QR is well conditioned.
  for (Eigen::Index c = 1; c < k; ++c) {
    const double scale = a.col(c).cwiseAbs().maxCoeff();
    if (scale > 0.0) a.col(c) /= scale;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  const Eigen::VectorXd ey = vy - a * qr.solve(vy);
  const Eigen::VectorXd ex = vx - a * qr.solve(vx);
  const double syy = ey.squaredNorm(), sxx = ex.squaredNorm();
  out.rows = rows.size();
  if (!(syy > 0.0) || !(sxx > 0.0)) return out;
  out.r = std::clamp(ey.dot(ex) / std::sqrt(syy * sxx), -1.0, 1.0);
  const double rho = Lag1Autocorrelation(ey) * Lag1Autocorrelation(ex);
  const double nd = static_cast<double>(m);
  out.n_eff = std::clamp(nd * (1.0 - rho) / (1.0 + rho), 3.0, nd);
  out.z = out.r * std::sqrt(out.n_eff - 2.0) / std::sqrt(std::max(1e-12, 1.0 - out.r * out.r));
  return out;
}

double NoiseMaeFromSecondDifferences(std::span<const double> r,
                                     std::span<const std::int64_t> segment, double trim) {
  std::vector<double> e;
  for (std::size_t i = 1; i + 1 < r.size() && i + 1 < segment.size(); ++i) {
    if (segment[i - 1] != segment[i] || segment[i + 1] != segment[i]) continue;
    const double v = r[i + 1] - 2.0 * r[i] + r[i - 1];
    if (std::isfinite(v)) e.push_back(std::fabs(v));
  }
  if (e.size() < 10) return std::nan("");
  trim = std::clamp(trim, 0.0, 0.5);
  const std::size_t keep =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::floor((1.0 - trim) * e.size())));
  std::nth_element(e.begin(), e.begin() + static_cast<std::ptrdiff_t>(keep - 1), e.end());
  const double trimmed_mean =
      std::accumulate(e.begin(), e.begin() + static_cast<std::ptrdiff_t>(keep), 0.0) /
      static_cast<double>(keep);
  // For |Z| half-normal, the mean below its (1 − trim) quantile c is
  // √(2/π)·(1 − exp(−c²/2))/(1 − trim); rescale to the untrimmed mean.
  double factor = 1.0;
  if (trim > 0.0) {
    const double c = TwoSidedNormalQuantile(trim);
    factor = (1.0 - std::exp(-0.5 * c * c)) / (1.0 - trim);
  }
  return trimmed_mean / factor / std::sqrt(6.0);
}

}  // namespace pvtwin

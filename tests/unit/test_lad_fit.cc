// LadFit against problems with known least-absolute-deviation solutions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/fit/lad_fit.h"

namespace pvtwin {
namespace {

// Σ|z − y_i| is minimised by the median of y.
TEST(LadFit, LocationEstimateIsTheMedian) {
  const std::vector<double> y = {0.12, 0.31, 0.35, 0.52, 0.9, 0.93, 0.97};  // median 0.52
  ResidualFunction f = [&y](const Eigen::VectorXd& z, Eigen::VectorXd* r) {
    r->resize(static_cast<Eigen::Index>(y.size()));
    for (std::size_t i = 0; i < y.size(); ++i) (*r)(static_cast<Eigen::Index>(i)) = z(0) - y[i];
    return true;
  };
  LadFitOptions o;
  o.ftol_rel = 1e-12;
  o.xtol = 1e-12;
  const LadFitResult res =
      LadFit(f, Eigen::VectorXd::Constant(1, 0.05), Eigen::VectorXd::Zero(1), o);
  EXPECT_NEAR(res.z(0), 0.52, 1e-4);
  EXPECT_NEAR(res.final_cost, 0.4 + 0.21 + 0.17 + 0.38 + 0.41 + 0.45, 1e-3);
  EXPECT_LE(res.final_cost, res.initial_cost);
}

// A line through data with a few gross outliers: L1 ignores them, least
// squares would not.
TEST(LadFit, LineFitIgnoresOutliers) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> x(200), y(200);
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = u(rng);
    y[i] = 0.3 + 0.45 * x[i];
    if (i % 20 == 0) y[i] += 5.0;  // 5 % outliers
  }
  ResidualFunction f = [&](const Eigen::VectorXd& z, Eigen::VectorXd* r) {
    r->resize(static_cast<Eigen::Index>(x.size()));
    for (std::size_t i = 0; i < x.size(); ++i) {
      (*r)(static_cast<Eigen::Index>(i)) = z(0) + z(1) * x[i] - y[i];
    }
    return true;
  };
  LadFitOptions o;
  o.ftol_rel = 1e-12;
  o.xtol = 1e-12;
  const LadFitResult res = LadFit(f, Eigen::Vector2d(0.9, 0.9), Eigen::Vector2d::Zero(), o);
  EXPECT_NEAR(res.z(0), 0.3, 1e-3);
  EXPECT_NEAR(res.z(1), 0.45, 1e-3);
  EXPECT_TRUE(res.converged) << res.message;
  EXPECT_NEAR(res.final_cost, 10 * 5.0, 1e-6);  // only the outliers remain
}

// The box is respected, and a dominant prior pulls the answer to z_ref.
TEST(LadFit, BoundsAndPrior) {
  ResidualFunction f = [](const Eigen::VectorXd& z, Eigen::VectorXd* r) {
    *r = Eigen::VectorXd::Constant(1, z(0) - 1.7);  // optimum outside the box
    return true;
  };
  const LadFitResult bounded =
      LadFit(f, Eigen::VectorXd::Constant(1, 0.2), Eigen::VectorXd::Zero(1), LadFitOptions{});
  EXPECT_DOUBLE_EQ(bounded.z(0), 1.0);
  LadFitOptions o;
  o.prior_weight = 100.0;  // O = |z − 1.7| + 100 (z − 0.4)²: minimum at 0.4 + 1/200
  o.ftol_rel = 1e-12;
  o.xtol = 1e-12;
  const LadFitResult pulled =
      LadFit(f, Eigen::VectorXd::Constant(1, 0.9), Eigen::VectorXd::Constant(1, 0.4), o);
  EXPECT_NEAR(pulled.z(0), 0.405, 1e-4);
}

// A curved valley (Rosenbrock's in L1 form): |a·(z1 − z0²)| + |b − z0|,
// each term over many rows with offsets symmetric about zero so that the
// optimum is z = (b, b²) = (0.8, 0.64). The iterations walk along the
// valley with steps the damping holds back; a stop on one small decrease
// ends far from the optimum, the stop that also asks the undamped step's
// promise does not.
TEST(LadFit, StopWaitsForTheUndampedPromiseInACurvedValley) {
  const double a = 300.0, b = 0.8;
  std::vector<double> offsets;
  for (int k = -20; k <= 20; ++k) offsets.push_back(1e-3 * k);
  ResidualFunction f = [&](const Eigen::VectorXd& z, Eigen::VectorXd* r) {
    const auto n = static_cast<Eigen::Index>(offsets.size());
    r->resize(2 * n);
    for (Eigen::Index k = 0; k < n; ++k) {
      (*r)(k) = a * (z(1) - z(0) * z(0)) + offsets[static_cast<std::size_t>(k)];
      (*r)(n + k) = b - z(0) + offsets[static_cast<std::size_t>(k)];
    }
    return true;
  };
  LadFitOptions o;
  o.ftol_rel = 1e-3;
  const Eigen::Vector2d start(0.05, 0.0), optimum(b, b * b);
  const LadFitResult guarded = LadFit(f, start, Eigen::Vector2d::Zero(), o);
  o.stop_promise_factor = 0.0;
  const LadFitResult plain = LadFit(f, start, Eigen::Vector2d::Zero(), o);
  EXPECT_TRUE(guarded.converged) << guarded.message;
  EXPECT_LT((guarded.z - optimum).cwiseAbs().maxCoeff(), 0.002);
  EXPECT_GT((plain.z - optimum).cwiseAbs().maxCoeff(), 0.1);  // what the guard prevents
  EXPECT_LT(guarded.final_cost, plain.final_cost);
}

// Residuals that bend along the step: r_i = u(z) + e_i with
// u(z) = (z − 0.3) + 2·(z − 0.3)² and offsets e_i symmetric about zero, so
// that the L1 optimum is u = 0, z = 0.3 (the other root lies outside the
// box). From z = 0.9 the linearised step lands at z ≈ 0.51, where u has
// kept 0.30 of its 1.32; the bend it saw there, e = 2·v², corrects the
// step to z ≈ 0.42 (u ≈ 0.15), as geodesic acceleration's second-order
// term does. One iteration, without the stretch so that only the
// correction differs.
TEST(LadFit, CorrectionForTheBendOfTheResidualsAlongTheStep) {
  std::vector<double> offsets;
  for (int k = -10; k <= 10; ++k) offsets.push_back(1e-3 * k);
  ResidualFunction f = [&](const Eigen::VectorXd& z, Eigen::VectorXd* r) {
    const double d = z(0) - 0.3;
    r->resize(static_cast<Eigen::Index>(offsets.size()));
    for (std::size_t k = 0; k < offsets.size(); ++k) {
      (*r)(static_cast<Eigen::Index>(k)) = d + 2.0 * d * d + offsets[k];
    }
    return true;
  };
  LadFitOptions o;
  o.max_iterations = 1;
  o.max_stretch = 1.0;
  const Eigen::VectorXd start = Eigen::VectorXd::Constant(1, 0.9);
  const LadFitResult corrected = LadFit(f, start, Eigen::VectorXd::Zero(1), o);
  o.max_correction = 0.0;
  const LadFitResult plain = LadFit(f, start, Eigen::VectorXd::Zero(1), o);
  std::printf("one step from 0.9 towards 0.3: plain to %.4f, corrected to %.4f\n", plain.z(0),
              corrected.z(0));
  EXPECT_EQ(corrected.corrected, 1);
  EXPECT_EQ(plain.corrected, 0);
  EXPECT_NEAR(plain.z(0), 0.9 - 1.32 / 3.4, 0.01);  // the Gauss–Newton step
  const double v = 1.32 / 3.4;
  EXPECT_NEAR(corrected.z(0), 0.9 - v - 2.0 * v * v / 3.4, 0.01);  // … corrected for e = 2·v²
  EXPECT_LT(corrected.final_cost, 0.6 * plain.final_cost);
}

// A line a + b·x through data whose unconstrained fit has a < 0, with x far
// from zero so that a and b are strongly coupled: on the box a stays at 0
// and b alone fits, its L1 optimum the weighted median of y_i/x_i (weights
// x_i). A step of both parameters clamped to the box assumes a moves and
// then does not move it, so b overshoots and only tiny damped steps are
// accepted; the step of the movable parameter alone lands at once.
TEST(LadFit, AParameterPinnedAtABoundDoesNotHoldBackTheOthers) {
  std::vector<double> x, y;
  for (int i = 0; i <= 40; ++i) {
    x.push_back(10.0 + 0.025 * i);
    y.push_back(-0.5 + 0.1 * x.back() + 1e-3 * ((i * 7) % 5 - 2));  // a = −0.5, b = 0.1
  }
  ResidualFunction f = [&](const Eigen::VectorXd& z, Eigen::VectorXd* r) {
    r->resize(static_cast<Eigen::Index>(x.size()));
    for (std::size_t i = 0; i < x.size(); ++i) {
      (*r)(static_cast<Eigen::Index>(i)) = z(0) + z(1) * x[i] - y[i];
    }
    return true;
  };
  // The weighted median of y_i/x_i, weights x_i.
  std::vector<std::pair<double, double>> ratios;
  double total = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    ratios.emplace_back(y[i] / x[i], x[i]);
    total += x[i];
  }
  std::sort(ratios.begin(), ratios.end());
  double below = 0.0, b_opt = 0.0;
  for (const auto& [ratio, weight] : ratios) {
    below += weight;
    if (below >= 0.5 * total) {
      b_opt = ratio;
      break;
    }
  }
  LadFitOptions o;
  o.ftol_rel = 1e-9;
  o.xtol = 1e-10;
  const LadFitResult res = LadFit(f, Eigen::Vector2d(0.5, 0.5), Eigen::Vector2d::Zero(), o);
  EXPECT_TRUE(res.converged) << res.message;
  EXPECT_DOUBLE_EQ(res.z(0), 0.0);
  // The data's pattern of offsets makes the optimum a short flat segment
  // of b around b_opt: the cost, not b, is unique.
  Eigen::VectorXd r_opt;
  f(Eigen::Vector2d(0.0, b_opt), &r_opt);
  EXPECT_NEAR(res.final_cost, r_opt.cwiseAbs().sum(), 1e-9);
  // 16 evaluations here; the clamped step alone (LadFit before 4a67403)
  // took 463, in tiny steps.
  EXPECT_LT(res.evaluations, 50) << res.message;
}

// Residuals of two parameters over `rows` rows, r_i = residual(i, z), and
// the Jacobian of rows gradient(i, z), which appends each point it is taken
// at to *points (before its rows are written).
struct RecordingModel {
  ResidualFunction residuals;
  JacobianFunction jacobian;
};
RecordingModel MakeRecordingModel(
    std::size_t rows, std::function<double(std::size_t, const Eigen::VectorXd&)> residual,
    std::function<Eigen::Vector2d(std::size_t, const Eigen::VectorXd&)> gradient,
    std::vector<Eigen::VectorXd>* points) {
  const auto n = static_cast<Eigen::Index>(rows);
  RecordingModel m;
  m.residuals = [n, residual](const Eigen::VectorXd& z, Eigen::VectorXd* r) {
    r->resize(n);
    for (Eigen::Index i = 0; i < n; ++i) (*r)(i) = residual(static_cast<std::size_t>(i), z);
    return true;
  };
  m.jacobian = [n, gradient, points](const Eigen::VectorXd& z, const Eigen::VectorXd&,
                                     Eigen::MatrixXd* jac) {
    points->push_back(z);
    jac->resize(n, 2);
    for (Eigen::Index i = 0; i < n; ++i) jac->row(i) = gradient(static_cast<std::size_t>(i), z);
    return true;
  };
  return m;
}

// The Jacobian is taken once per point: an iteration after a rejected one
// (sharper weight floor, same point) reuses it. The result carries the
// last Jacobian and how far the returned point is from where it was taken.
// The median of LocationEstimateIsTheMedian, whose kink rejects steps, on a
// line z0 + z1·x so that the Jacobian depends on nothing but x.
TEST(LadFit, TakesEachJacobianOnceAndReturnsTheLast) {
  const std::vector<double> x = {0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  const std::vector<double> y = {0.12, 0.31, 0.35, 0.52, 0.9, 0.93, 0.97};
  std::vector<Eigen::VectorXd> points;
  const RecordingModel m = MakeRecordingModel(
      y.size(), [&](std::size_t i, const Eigen::VectorXd& z) { return z(0) + z(1) * x[i] - y[i]; },
      [&](std::size_t i, const Eigen::VectorXd&) {
        // The first row's slope tells the calls apart.
        const double d0 = i == 0 ? 1.0 + static_cast<double>(points.size()) : 1.0;
        return Eigen::Vector2d(d0, x[i]);
      },
      &points);
  LadFitOptions o;
  o.ftol_rel = 1e-12;
  o.xtol = 1e-12;
  const LadFitResult res =
      LadFit(m.residuals, Eigen::Vector2d(0.05, 0.05), Eigen::Vector2d::Zero(), o, m.jacobian);
  ASSERT_GE(points.size(), 2u);
  EXPECT_LT(static_cast<int>(points.size()), res.iterations) << "no iteration reused a Jacobian";
  for (std::size_t k = 1; k < points.size(); ++k) EXPECT_NE(points[k], points[k - 1]) << k;
  EXPECT_DOUBLE_EQ(res.jacobian_distance, (res.z - points.back()).cwiseAbs().maxCoeff());
  ASSERT_EQ(res.jacobian.rows(), static_cast<Eigen::Index>(y.size()));
  EXPECT_DOUBLE_EQ(res.jacobian(0, 0), 1.0 + static_cast<double>(points.size()));
}

// An exponential decay y = a·e^(−b·t) with Gaussian noise, z = (a/2, b/5),
// fitted from near its optimum with a Jacobian that costs five runs: after
// each short accepted step one iteration takes Broyden's update of the last
// Jacobian (LadFitOptions::secant_max_step) instead of a new one. It ends
// at the fit without the update (the same L1 optimum to 1e-6 of the cost)
// with fewer Jacobians, each taken at a new point, and returns the last
// Jacobian taken. On this nearly linear valley the rank-one term itself
// changes little (the last Jacobian unchanged ends with the same counts);
// the test is about the iteration that saves a Jacobian, not the term.
TEST(LadFit, ASecantIterationAfterAShortStepSavesJacobians) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<double> t(3000), y(3000);
  for (std::size_t i = 0; i < t.size(); ++i) {
    t[i] = 2.0 * static_cast<double>(i) / static_cast<double>(t.size());
    y[i] = 1.2 * std::exp(-1.5 * t[i]) + noise(rng);
  }
  std::vector<Eigen::VectorXd> points;
  const RecordingModel m = MakeRecordingModel(
      t.size(),
      [&](std::size_t i, const Eigen::VectorXd& z) {
        return 2.0 * z(0) * std::exp(-5.0 * z(1) * t[i]) - y[i];
      },
      [&](std::size_t i, const Eigen::VectorXd& z) {
        const double e = std::exp(-5.0 * z(1) * t[i]);
        return Eigen::Vector2d(2.0 * e, -10.0 * z(0) * t[i] * e);
      },
      &points);
  LadFitOptions o;
  o.ftol_rel = 1e-10;
  o.jacobian_cost = 5;
  const Eigen::Vector2d start(0.66, 0.27);  // the optimum is near (0.6, 0.3)
  o.secant_max_step = 0.0;
  const LadFitResult exact = LadFit(m.residuals, start, Eigen::Vector2d::Zero(), o, m.jacobian);
  const std::size_t exact_jacobians = points.size();
  points.clear();
  o.secant_max_step = 0.05;
  const LadFitResult secant = LadFit(m.residuals, start, Eigen::Vector2d::Zero(), o, m.jacobian);
  std::printf("Jacobians %zu without the secant iteration, %zu with; iterations %d and %d\n",
              exact_jacobians, points.size(), exact.iterations, secant.iterations);
  EXPECT_NEAR(secant.final_cost, exact.final_cost, 1e-6 * exact.final_cost);
  EXPECT_LT((secant.z - exact.z).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_LT(points.size(), exact_jacobians);
  EXPECT_LT(static_cast<int>(points.size()), secant.iterations) << "no secant iteration";
  for (std::size_t k = 1; k < points.size(); ++k) EXPECT_NE(points[k], points[k - 1]) << k;
  EXPECT_DOUBLE_EQ(secant.jacobian_distance, (secant.z - points.back()).cwiseAbs().maxCoeff());
}

// A line through 4000 rows with Gaussian noise (the plant's residuals near
// the optimum are mostly noise); residuals of z = (intercept, slope).
ResidualFunction NoisyLine(std::vector<double>* x, std::vector<double>* y) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.02);
  x->resize(4000);
  y->resize(4000);
  for (std::size_t i = 0; i < x->size(); ++i) {
    (*x)[i] = u(rng);
    (*y)[i] = 0.3 + 0.45 * (*x)[i] + noise(rng);
  }
  return [x, y](const Eigen::VectorXd& z, Eigen::VectorXd* r) {
    r->resize(static_cast<Eigen::Index>(x->size()));
    for (std::size_t i = 0; i < x->size(); ++i) {
      (*r)(static_cast<Eigen::Index>(i)) = z(0) + z(1) * (*x)[i] - (*y)[i];
    }
    return true;
  };
}

// On the noisy line the IRLS weights 1/max(|r|, δ) overstate the curvature
// of the L1 sum about 2.5 times, so each unstretched step covers about 0.4
// of the way to the optimum along its line. The stretch to the line's
// predicted minimiser closes most of the rest with one more evaluation.
TEST(LadFit, StretchedStepsCloseTheGapTheWeightsLeave) {
  std::vector<double> x, y;
  const ResidualFunction f = NoisyLine(&x, &y);
  LadFitOptions o;
  o.n_scale = static_cast<double>(x.size());
  o.ftol_rel = 1e-14;
  o.xtol = 1e-14;
  const Eigen::Vector2d start(0.1, 0.9);
  const double optimum = LadFit(f, start, Eigen::Vector2d::Zero(), o).final_cost;
  o.max_iterations = 3;
  const LadFitResult stretched = LadFit(f, start, Eigen::Vector2d::Zero(), o);
  o.max_stretch = 1.0;
  const LadFitResult plain = LadFit(f, start, Eigen::Vector2d::Zero(), o);
  EXPECT_GT(stretched.stretched, 0);
  EXPECT_EQ(plain.stretched, 0);
  const double gap_stretched = stretched.final_cost - optimum;
  const double gap_plain = plain.final_cost - optimum;
  std::printf("gap after 3 iterations: stretched %.3g (%d evaluations), plain %.3g (%d)\n",
              gap_stretched, stretched.evaluations, gap_plain, plain.evaluations);
  EXPECT_GE(gap_stretched, -1e-12);
  EXPECT_LT(gap_stretched, 0.1 * gap_plain);
}

// A fit ends where its last Jacobian was taken when the next step is
// predicted to gain less than ftol (its undamped promise times what the
// last step gained per unit of promise), instead of taking that step and
// leaving the caller's identifiability analysis a Jacobian one step back.
// The end is still within ftol of the optimum.
TEST(LadFit, EndsAtItsLastJacobianWhenTheNextStepCannotGainFtol) {
  std::vector<double> x, y;
  const ResidualFunction f = NoisyLine(&x, &y);
  JacobianFunction jacobian = [&x](const Eigen::VectorXd&, const Eigen::VectorXd&,
                                   Eigen::MatrixXd* jac) {
    jac->resize(static_cast<Eigen::Index>(x.size()), 2);
    for (std::size_t i = 0; i < x.size(); ++i) {
      (*jac)(static_cast<Eigen::Index>(i), 0) = 1.0;
      (*jac)(static_cast<Eigen::Index>(i), 1) = x[i];
    }
    return true;
  };
  LadFitOptions o;
  o.n_scale = static_cast<double>(x.size());
  o.ftol_rel = 1e-14;
  o.xtol = 1e-14;
  const Eigen::Vector2d start(0.1, 0.9);
  const double optimum = LadFit(f, start, Eigen::Vector2d::Zero(), o, jacobian).final_cost;
  o.ftol_rel = 1e-3;
  o.xtol = 1e-7;
  const LadFitResult res = LadFit(f, start, Eigen::Vector2d::Zero(), o, jacobian);
  EXPECT_TRUE(res.converged) << res.message;
  EXPECT_NE(res.message.find("predicted"), std::string::npos) << res.message;
  EXPECT_EQ(res.jacobian_distance, 0.0);
  EXPECT_LE(res.final_cost - optimum, 1e-3 * optimum);
}

TEST(LadFit, NonFiniteStartIsReported) {
  ResidualFunction f = [](const Eigen::VectorXd&, Eigen::VectorXd* r) {
    *r = Eigen::VectorXd::Constant(3, std::nan(""));
    return false;
  };
  const LadFitResult res =
      LadFit(f, Eigen::VectorXd::Constant(2, 0.5), Eigen::VectorXd::Zero(2), LadFitOptions{});
  EXPECT_FALSE(res.converged);
  EXPECT_NE(res.message.find("non-finite"), std::string::npos);
  EXPECT_EQ(res.evaluations, 1);
}

// JᵀW·J and JᵀW·r on both sides of the split into halves, with the rows
// not a multiple of the summing blocks. Entries, weights and residuals are
// small integers, so that every partial sum is exact in any order: the
// sums must equal the integer sums to the bit, on one thread and on two.
TEST(WeightedNormalEquations, ExactSumsOnBothSidesOfTheSplitOnOneThreadAndTwo) {
  for (const Eigen::Index rows : {Eigen::Index{5001}, kSplitNormalEquationsRows + 3001}) {
    constexpr Eigen::Index n = 3;
    Eigen::MatrixXd jac(rows, n);
    Eigen::VectorXd w(rows), r(rows);
    std::int64_t h_exact[n][n] = {}, g_exact[n] = {}, gram_exact[n][n] = {};
    for (Eigen::Index i = 0; i < rows; ++i) {
      const std::int64_t col[n] = {1, i % 7 - 3, (i * 13) % 11 - 5};
      const std::int64_t wi = i % 3 == 0 ? 2 : 1;
      const std::int64_t ri = (i * 7) % 9 - 4;
      for (Eigen::Index a = 0; a < n; ++a) {
        jac(i, a) = static_cast<double>(col[a]);
        g_exact[a] += col[a] * wi * ri;
        for (Eigen::Index b = 0; b < n; ++b) {
          h_exact[a][b] += col[a] * wi * col[b];
          gram_exact[a][b] += col[a] * col[b];
        }
      }
      w(i) = static_cast<double>(wi);
      r(i) = static_cast<double>(ri);
    }
    for (const int threads : {1, 2}) {
      SCOPED_TRACE("rows " + std::to_string(rows) + ", threads " + std::to_string(threads));
      Eigen::MatrixXd h, gram;
      Eigen::VectorXd g, untouched = Eigen::VectorXd::Constant(2, 7.0);
      WeightedNormalEquations(jac, w, r, threads, &h, &g);
      WeightedNormalEquations(jac, Eigen::VectorXd(), Eigen::VectorXd(), threads, &gram,
                              &untouched);
      ASSERT_EQ(h.rows(), n);
      ASSERT_EQ(h.cols(), n);
      ASSERT_EQ(g.size(), n);
      for (Eigen::Index a = 0; a < n; ++a) {
        EXPECT_EQ(g(a), static_cast<double>(g_exact[a]));
        for (Eigen::Index b = 0; b < n; ++b) {
          EXPECT_EQ(h(a, b), static_cast<double>(h_exact[a][b]));
          EXPECT_EQ(gram(a, b), static_cast<double>(gram_exact[a][b]));
        }
      }
      EXPECT_EQ(untouched, Eigen::VectorXd::Constant(2, 7.0));  // JᵀJ alone: g left alone
    }
  }
}

// With real entries the order of the sums shows in the last bits: above the
// split the halves are summed apart on one thread as on two, so the results
// are the same to the bit; both stay within rounding of one plain product.
TEST(WeightedNormalEquations, TheSameToTheBitOnOneThreadAndTwo) {
  const Eigen::Index rows = kSplitNormalEquationsRows + 777;
  constexpr Eigen::Index n = 4;
  std::mt19937 rng(16);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd jac(rows, n);
  Eigen::VectorXd w(rows), r(rows);
  for (Eigen::Index i = 0; i < rows; ++i) {
    for (Eigen::Index a = 0; a < n; ++a) jac(i, a) = normal(rng);
    w(i) = 1.0 / (0.1 + std::fabs(normal(rng)));
    r(i) = normal(rng);
  }
  Eigen::MatrixXd h1, h2;
  Eigen::VectorXd g1, g2;
  WeightedNormalEquations(jac, w, r, 1, &h1, &g1);
  WeightedNormalEquations(jac, w, r, 2, &h2, &g2);
  EXPECT_EQ(h1, h2);
  EXPECT_EQ(g1, g2);
  const Eigen::MatrixXd wj = jac.array().colwise() * w.array();
  const Eigen::MatrixXd h_plain = jac.transpose() * wj;
  const Eigen::VectorXd g_plain = wj.transpose() * r;
  EXPECT_LE((h1 - h_plain).cwiseAbs().maxCoeff(), 1e-12 * h_plain.cwiseAbs().maxCoeff());
  const Eigen::VectorXd g_size = wj.cwiseAbs().transpose() * r.cwiseAbs();
  EXPECT_LE((g1 - g_plain).cwiseAbs().maxCoeff(), 1e-12 * g_size.maxCoeff());
}

}  // namespace
}  // namespace pvtwin

// LadFit against problems with known least-absolute-deviation solutions.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

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

}  // namespace
}  // namespace pvtwin

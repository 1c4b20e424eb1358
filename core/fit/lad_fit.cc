#include "core/fit/lad_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "core/common/threads.h"

namespace pvtwin {

namespace {

// A stretch shorter than this is not worth its run.
constexpr double kMinStretch = 1.25;

double Objective(const Eigen::VectorXd& r, const Eigen::VectorXd& z, const Eigen::VectorXd& z_ref,
                 const LadFitOptions& o) {
  return r.cwiseAbs().sum() / o.n_scale + o.prior_weight * (z - z_ref).squaredNorm();
}

constexpr Eigen::Index kBlockRows = 2048;

// The sums of WeightedNormalEquations over the rows [begin, end) by blocks
// of kBlockRows rows (begin a multiple of it) through one block's buffer,
// without a weighted copy of the whole Jacobian: at 5-s data that copy was
// 42 MB, fresh pages from the kernel on every iteration.
void SumNormalEquations(const Eigen::MatrixXd& jac, const Eigen::VectorXd& w,
                        const Eigen::VectorXd& r, Eigen::Index begin, Eigen::Index end,
                        Eigen::MatrixXd* h, Eigen::VectorXd* g) {
  const Eigen::Index n = jac.cols();
  h->setZero(n, n);
  if (w.size() > 0) g->setZero(n);
  Eigen::MatrixXd buffer;
  for (Eigen::Index start = begin; start < end; start += kBlockRows) {
    const Eigen::Index b = std::min(kBlockRows, end - start);
    const auto block = jac.middleRows(start, b);
    if (w.size() == 0) {
      // The upper triangle by column products of the block, which stays in
      // the cache: half the product's multiplications.
      for (Eigen::Index a = 0; a < n; ++a) {
        for (Eigen::Index c = a; c < n; ++c) (*h)(a, c) += block.col(a).dot(block.col(c));
      }
      continue;
    }
    buffer.resize(b, n);
    buffer.noalias() = (block.array().colwise() * w.segment(start, b).array()).matrix();
    // The lower triangle alone (Eigen's triangular product, the same sums
    // to the bit as the lower half of the full product): a fifth less time
    // at 11 columns.
    h->triangularView<Eigen::Lower>() += block.transpose() * buffer;
    g->noalias() += buffer.transpose() * r.segment(start, b);
  }
  // H is symmetric; mirror the triangle that was summed.
  if (w.size() > 0) {
    h->triangularView<Eigen::StrictlyUpper>() = h->transpose();
    return;
  }
  for (Eigen::Index a = 1; a < n; ++a) {
    for (Eigen::Index c = 0; c < a; ++c) (*h)(a, c) = (*h)(c, a);
  }
}

}  // namespace

void WeightedNormalEquations(const Eigen::MatrixXd& jac, const Eigen::VectorXd& w,
                             const Eigen::VectorXd& r, int threads, Eigen::MatrixXd* h,
                             Eigen::VectorXd* g) {
  const Eigen::Index rows = jac.rows();
  if (rows < kSplitNormalEquationsRows) {
    SumNormalEquations(jac, w, r, 0, rows, h, g);
    return;
  }
  // The halves meet at a block boundary: the blocks are those of one sum.
  const Eigen::Index half = (rows / 2 + kBlockRows - 1) / kBlockRows * kBlockRows;
  Eigen::MatrixXd h_second;
  Eigen::VectorXd g_second;
  auto first = [&] { SumNormalEquations(jac, w, r, 0, half, h, g); };
  auto second = [&] { SumNormalEquations(jac, w, r, half, rows, &h_second, &g_second); };
  if (threads > 1) {
    RunBoth(second, first);
  } else {
    first();
    second();
  }
  *h += h_second;
  if (w.size() > 0) *g += g_second;
}

namespace {

// s solving (H + λ·D) s = −g, D the diagonal of H floored so that a
// direction without curvature is damped too (λ = 0: the undamped step).
// Not for an empty system.
Eigen::VectorXd DampedStep(const Eigen::MatrixXd& h, const Eigen::VectorXd& g, double lambda) {
  const double floor = 1e-12 * h.diagonal().maxCoeff() + 1e-300;
  Eigen::MatrixXd damped = h;
  damped.diagonal() += lambda * h.diagonal().cwiseMax(floor);
  if (lambda == 0.0) damped.diagonal().array() += floor;
  return -damped.ldlt().solve(g);
}

// The majoriser's change along s: gᵀs + ½·sᵀHs.
double ModelChange(const Eigen::MatrixXd& h, const Eigen::VectorXd& g, const Eigen::VectorXd& s) {
  return g.dot(s) + 0.5 * s.dot(h * s);
}

// Broyden's rank-one secant update of the last Jacobian J (taken at the
// start of an accepted step s): J + u·vᵀ with v = s and
// u = (r_new − r_old − J·s) / sᵀs, which maps s to the change of the
// residuals the step's runs measured. It stands in for a new Jacobian for
// one iteration (LadFitOptions::secant_max_step); J itself is kept as it
// was taken.
struct Secant {
  bool active = false;
  Eigen::VectorXd u, v;

  // Sets u and v from the step s = z_new − z_old of J's iteration.
  void Set(const Eigen::MatrixXd& jac, const Eigen::VectorXd& s, const Eigen::VectorXd& r_old,
           const Eigen::VectorXd& r_new) {
    u.noalias() = r_new - r_old;
    u.noalias() -= jac * s;
    u /= s.squaredNorm();
    v = s;
    active = true;
  }

  // y − (J + u·vᵀ)·x into *out, from y − J·x.
  void SubtractTimes(const Eigen::VectorXd& x, Eigen::VectorXd* out) const {
    if (active) out->noalias() -= u * v.dot(x);
  }

  // c·(J + u·vᵀ)ᵀ·y into *out, from c·Jᵀ·y.
  void AddTransposeTimes(const Eigen::VectorXd& y, double c, Eigen::VectorXd* out) const {
    if (active) *out += v * (c * u.dot(y));
  }
};

// The quadratic majoriser of one iteration: H = JᵀWJ / N + 2p·I and
// g = JᵀW r / N + 2p (z − z_ref), with both restricted to the parameters
// free to move from z: all but those at a bound of the unit box whose
// gradient points out of it.
struct Majoriser {
  Eigen::MatrixXd h, h_movable;
  Eigen::VectorXd g, g_movable;
  std::vector<Eigen::Index> movable;

  // H and g at z from the Jacobian (with the secant update when active),
  // the IRLS weights and the residuals there.
  void Build(const Eigen::MatrixXd& jac, const Secant& secant, const Eigen::VectorXd& w,
             const Eigen::VectorXd& r, const Eigen::VectorXd& z, const Eigen::VectorXd& z_ref,
             const LadFitOptions& o) {
    WeightedNormalEquations(jac, w, r, o.threads, &h, &g);
    if (secant.active) {
      // (J + u·vᵀ)ᵀW(J + u·vᵀ) = JᵀWJ + a·vᵀ + v·aᵀ + (uᵀWu)·v·vᵀ with
      // a = JᵀWu, and (J + u·vᵀ)ᵀW·r = JᵀW·r + (uᵀW·r)·v.
      const Eigen::VectorXd wu = w.cwiseProduct(secant.u);
      const Eigen::VectorXd a = jac.transpose() * wu;
      const Eigen::VectorXd& v = secant.v;
      h.noalias() += a * v.transpose();
      h.noalias() += v * a.transpose();
      h.noalias() += (wu.dot(secant.u) * v) * v.transpose();
      g.noalias() += wu.dot(r) * v;
    }
    h /= o.n_scale;
    g /= o.n_scale;
    h.diagonal().array() += 2.0 * o.prior_weight;
    g += 2.0 * o.prior_weight * (z - z_ref);
    SetMovable(z);
  }

  void SetMovable(const Eigen::VectorXd& z) {
    movable.clear();
    for (Eigen::Index j = 0; j < z.size(); ++j) {
      const bool pinned = (z(j) <= 0.0 && g(j) > 0.0) || (z(j) >= 1.0 && g(j) < 0.0);
      if (!pinned) movable.push_back(j);
    }
    h_movable = h(movable, movable);
    g_movable = g(movable);
  }

  // What the undamped step promises over the movable parameters, ½·gᵀH⁻¹g.
  double Promised() const {
    return movable.empty() ? 0.0 : -0.5 * g_movable.dot(DampedStep(h_movable, g_movable, 0.0));
  }

  // The point tried from z with damping λ. The damped step of all
  // parameters, clamped to the box: with a parameter pinned at a bound that
  // step assumes it moves, and the others' steps, coupled to it, go astray
  // once it does not (the misspecified fits crawled on tiny accepted steps
  // with a promise many times what they kept). So the step of the movable
  // parameters alone (the pinned ones stay) is a second candidate, and the
  // one the majoriser predicts lower is tried. Neither alone is best: the
  // second can hold a parameter at the bound an early long step threw it
  // to, where the first would have pulled it back.
  Eigen::VectorXd TrialPoint(const Eigen::VectorXd& z, double lambda) const {
    Eigen::VectorXd z_all = (z + DampedStep(h, g, lambda)).cwiseMax(0.0).cwiseMin(1.0);
    if (movable.empty() || movable.size() == static_cast<std::size_t>(z.size())) return z_all;
    const Eigen::VectorXd step_movable = DampedStep(h_movable, g_movable, lambda);
    Eigen::VectorXd z_movable = z;
    z_movable(movable) += step_movable;
    z_movable = z_movable.cwiseMax(0.0).cwiseMin(1.0);
    return ModelChange(h, g, z_movable - z) < ModelChange(h, g, z_all - z) ? z_movable : z_all;
  }
};

// The longest stretch of the accepted step s from z (z + α·s, α ≥ 1) that
// stays in the unit box, capped at max_stretch.
double BoxStretch(const Eigen::VectorXd& z, const Eigen::VectorXd& s, double max_stretch) {
  double alpha = max_stretch;
  for (Eigen::Index j = 0; j < z.size(); ++j) {
    if (s(j) > 0.0) alpha = std::min(alpha, (1.0 - z(j)) / s(j));
    if (s(j) < 0.0) alpha = std::min(alpha, -z(j) / s(j));
  }
  return alpha;
}

// The minimiser over α in [1, alpha_max] of the objective along the line
// through the last point (residuals r0, α = 0) and the accepted trial
// (residuals r1, α = 1), the residuals interpolated linearly: r0 + α·d,
// d = r1 − r0 (a secant, exact at both ends). That line objective is
// convex (an L1 sum plus the quadratic prior), so bisection on its
// derivative finds it; 1 when the derivative at 1 is not negative.
double LineMinimiser(const Eigen::VectorXd& r0, const Eigen::VectorXd& d, const Eigen::VectorXd& z,
                     const Eigen::VectorXd& s, const Eigen::VectorXd& z_ref, const LadFitOptions& o,
                     double alpha_max) {
  const double ss = s.squaredNorm();
  const double sz = s.dot(z - z_ref);
  auto slope = [&](double alpha) {
    double acc = 0.0;
    for (Eigen::Index i = 0; i < r0.size(); ++i) {
      // sign(r_i)·d_i without a branch: the signs of noisy residuals are
      // what a branch predictor cannot guess.
      acc += std::copysign(1.0, r0(i) + alpha * d(i)) * d(i);
    }
    return acc / o.n_scale + 2.0 * o.prior_weight * (sz + alpha * ss);
  };
  if (!(slope(1.0) < 0.0)) return 1.0;
  if (slope(alpha_max) <= 0.0) return alpha_max;
  double lo = 1.0, hi = alpha_max;
  for (int k = 0; k < 10; ++k) {
    const double mid = 0.5 * (lo + hi);
    (slope(mid) < 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Forward-difference Jacobian at z (residuals r), stepping inwards at the
// upper bound; a non-finite column gives no direction.
void ForwardDifferences(const ResidualFunction& residuals, const Eigen::VectorXd& z,
                        const Eigen::VectorXd& r, const LadFitOptions& o, Eigen::MatrixXd* jac,
                        Eigen::VectorXd* r_step, LadFitResult* res) {
  for (Eigen::Index j = 0; j < z.size(); ++j) {
    Eigen::VectorXd zp = z;
    const double h = z(j) + o.jacobian_step <= 1.0 ? o.jacobian_step : -o.jacobian_step;
    zp(j) += h;
    ++res->evaluations;
    if (!residuals(zp, r_step)) *r_step = r;
    jac->col(j) = (*r_step - r) / h;
  }
}

// The trial z + v (residuals r_trial, cost *trial_cost) corrected for the
// bend of the residuals along v (LadFitOptions::max_correction): the
// majoriser's step for e = r_trial − r − J·v over the parameters v moves,
// with the trial's damping. The corrected point replaces the trial if it
// is lower (then returns true). `bend` is scratch of the rows' size.
bool CorrectForBend(const ResidualFunction& residuals, const Eigen::VectorXd& z,
                    const Eigen::VectorXd& r, const Eigen::MatrixXd& jac, const Secant& secant,
                    const Eigen::VectorXd& w, const Eigen::MatrixXd& h, double lambda,
                    const Eigen::VectorXd& z_ref, const LadFitOptions& o, Eigen::VectorXd* z_trial,
                    Eigen::VectorXd* r_trial, double* trial_cost, Eigen::VectorXd* bend,
                    Eigen::VectorXd* r_scratch, LadFitResult* res) {
  if (!(o.max_correction > 0.0) || res->evaluations >= o.max_evaluations) return false;
  const Eigen::VectorXd v = *z_trial - z;
  std::vector<Eigen::Index> moved;
  for (Eigen::Index j = 0; j < v.size(); ++j) {
    if (v(j) != 0.0) moved.push_back(j);
  }
  if (moved.empty()) return false;
  bend->noalias() = *r_trial - r;
  bend->noalias() -= jac * v;
  secant.SubtractTimes(v, bend);
  bend->array() *= w.array();
  Eigen::VectorXd jwe = jac.transpose() * *bend / o.n_scale;
  secant.AddTransposeTimes(*bend, 1.0 / o.n_scale, &jwe);
  const Eigen::VectorXd c_moved = DampedStep(h(moved, moved), jwe(moved), lambda);
  const double ratio = c_moved.cwiseAbs().maxCoeff() / v.cwiseAbs().maxCoeff();
  if (!(ratio >= o.min_correction && ratio <= o.max_correction)) return false;
  Eigen::VectorXd z_c = *z_trial;
  z_c(moved) += c_moved;
  z_c = z_c.cwiseMax(0.0).cwiseMin(1.0);
  ++res->evaluations;
  if (!residuals(z_c, r_scratch)) return false;
  const double c_cost = Objective(*r_scratch, z_c, z_ref, o);
  if (!(c_cost < *trial_cost)) return false;
  *z_trial = z_c;
  r_trial->swap(*r_scratch);
  *trial_cost = c_cost;
  return true;
}

// An accepted step from z (residuals r_z) to *z_to (residuals *r_to, cost
// *cost_to): the IRLS majoriser overstates the curvature of the L1
// objective (weights 1/|r| against a density of residuals near zero), so
// its steps fall short of the optimum along their own line, and the fit
// converged linearly, each iteration halving what was left. The line's
// minimiser predicted from the two residual vectors (LineMinimiser) is
// tried with one more run and kept if lower.
void StretchStep(const ResidualFunction& residuals, const Eigen::VectorXd& z,
                 const Eigen::VectorXd& r_z, const Eigen::VectorXd& z_ref, const LadFitOptions& o,
                 Eigen::VectorXd* z_to, Eigen::VectorXd* r_to, double* cost_to,
                 Eigen::VectorXd* r_scratch, LadFitResult* res) {
  if (!(o.max_stretch > 1.0) || res->evaluations >= o.max_evaluations) return;
  const Eigen::VectorXd s = *z_to - z;
  const double alpha_max = BoxStretch(z, s, o.max_stretch);
  if (alpha_max < kMinStretch) return;
  const double alpha = LineMinimiser(r_z, *r_to - r_z, z, s, z_ref, o, alpha_max);
  if (alpha < kMinStretch) return;
  const Eigen::VectorXd z_long = (z + alpha * s).cwiseMax(0.0).cwiseMin(1.0);
  ++res->evaluations;
  if (!residuals(z_long, r_scratch)) return;
  const double long_cost = Objective(*r_scratch, z_long, z_ref, o);
  if (!(long_cost < *cost_to)) return;
  *z_to = z_long;
  r_to->swap(*r_scratch);
  *cost_to = long_cost;
  ++res->stretched;
}

// The IRLS weights at the residuals r into *w (its storage reused): 1/|r|,
// with |r| floored at floor_rel times its mean.
void IrlsWeights(const Eigen::VectorXd& r, double floor_rel, Eigen::VectorXd* w) {
  const double delta = std::max(floor_rel * r.cwiseAbs().mean(), 1e-12);
  *w = r.cwiseAbs().cwiseMax(delta).cwiseInverse();
}

// The Jacobian at z: a run with sensitivities when `jacobian` gives one
// (counted as jacobian_cost evaluations), forward differences otherwise.
void TakeJacobian(const ResidualFunction& residuals, const JacobianFunction& jacobian,
                  Eigen::Index jacobian_cost, const Eigen::VectorXd& z, const Eigen::VectorXd& r,
                  const LadFitOptions& o, Eigen::MatrixXd* jac, Eigen::VectorXd* r_step,
                  LadFitResult* res) {
  if (jacobian && jacobian(z, r, jac)) {
    res->evaluations += static_cast<int>(jacobian_cost);
  } else {
    ForwardDifferences(residuals, z, r, o, jac, r_step, res);
  }
}

// A small decrease (below ftol_rel of the new cost) ends the fit if the
// undamped step of the iteration's majoriser promised little too, or if it
// is the third small one in a row: one short, damped step of a fit still
// making its way along a valley does not stop it, and a promise the steps
// do not keep (a flat direction) does not hold it for long. Counts the
// small decreases in a row in *small_in_a_row.
bool SmallDecreaseStops(double decrease, double cost, double promised, const LadFitOptions& o,
                        int* small_in_a_row) {
  const bool small = decrease <= o.ftol_rel * cost;
  *small_in_a_row = small ? *small_in_a_row + 1 : 0;
  return small && (o.stop_promise_factor <= 0.0 || *small_in_a_row >= 3 ||
                   promised <= o.stop_promise_factor * o.ftol_rel * cost);
}

}  // namespace

LadFitResult LadFit(const ResidualFunction& residuals, const Eigen::VectorXd& z0,
                    const Eigen::VectorXd& z_ref, const LadFitOptions& o,
                    const JacobianFunction& jacobian) {
  LadFitResult res;
  const Eigen::Index n = z0.size();
  Eigen::VectorXd z = z0.cwiseMax(0.0).cwiseMin(1.0);
  Eigen::VectorXd r, r_trial, r_step, bend;
  auto eval = [&](const Eigen::VectorXd& at, Eigen::VectorXd* out) {
    ++res.evaluations;
    return residuals(at, out);
  };
  if (!eval(z, &r)) {
    res.z = z;
    res.initial_cost = res.final_cost = std::nan("");
    res.message = "non-finite residuals at the start point";
    return res;
  }
  double cost = Objective(r, z, z_ref, o);
  res.initial_cost = cost;
  double lambda = 1e-3;
  Eigen::MatrixXd jac(r.size(), n);
  Eigen::VectorXd w;
  Majoriser maj;
  bool have_jac = false;  // jac was computed, at z_jac
  Eigen::VectorXd z_jac;
  Secant secant;  // active: the next iteration takes jac with this update
  double floor_rel = o.weight_floor_rel;
  int small_in_a_row = 0;  // accepted steps in a row that lowered O by less than ftol
  double gain_per_promise = std::numeric_limits<double>::infinity();  // of the last accepted step
  const Eigen::Index jacobian_cost = jacobian ? o.jacobian_cost : n;
  for (int it = 0; it < o.max_iterations; ++it) {
    const bool on_secant = secant.active;
    const bool jacobian_due = !on_secant && !(have_jac && z == z_jac);
    if (res.evaluations + (jacobian_due ? jacobian_cost : 0) + 1 > o.max_evaluations) {
      res.message = "evaluation budget reached";
      break;
    }
    ++res.iterations;
    IrlsWeights(r, floor_rel, &w);
    // One step past the last Jacobian its secant update stands in; still
    // where it was taken (a sharper weight floor after a rejected
    // iteration) only the weights change.
    if (jacobian_due) {
      TakeJacobian(residuals, jacobian, jacobian_cost, z, r, o, &jac, &r_step, &res);
      have_jac = true;
      z_jac = z;
    }
    const double lambda_at_start = lambda;
    maj.Build(jac, secant, w, r, z, z_ref, o);
    const double promised = maj.Promised();
    // The stop before a step asks stop_prediction_factor of ftol of this cost
    // (0.3 as the small-decrease rule asks of a promise, 1 in a polish).
    const double small_promise = o.stop_prediction_factor * o.ftol_rel * cost;
    // A step predicted to gain less than that ends the fit before it is
    // tried: the result then sits where its Jacobian was taken, which the
    // caller's identifiability analysis reuses, not one short step away.
    // The prediction is the undamped promise times what the last accepted
    // step gained per unit of its promise (the majoriser understates the
    // gain, about 2.5 times for noise-like residuals, far more while its
    // weight floor smooths a kink away); none before the first accepted
    // step, nor once the weight floor has been sharpened (the fit is then
    // after a kink the smoothing hid, which no promise foresees).
    if (o.stop_promise_factor > 0.0 && floor_rel == o.weight_floor_rel &&
        promised * gain_per_promise <= small_promise) {
      res.converged = true;
      res.message = "the next step is predicted to gain less than ftol";
      break;
    }
    bool accepted = false;
    double step_norm = 0.0;
    double new_cost = cost;
    for (int tries = 0; tries < 12 && res.evaluations < o.max_evaluations; ++tries) {
      Eigen::VectorXd z_new = maj.TrialPoint(z, lambda);
      step_norm = (z_new - z).cwiseAbs().maxCoeff();
      if (!(step_norm > 0.0) || !eval(z_new, &r_trial)) {
        lambda *= 4.0;
        continue;
      }
      new_cost = Objective(r_trial, z_new, z_ref, o);
      const bool corrected = CorrectForBend(residuals, z, r, jac, secant, w, maj.h, lambda, z_ref,
                                            o, &z_new, &r_trial, &new_cost, &bend, &r_step, &res);
      if (new_cost < cost) {
        if (corrected) ++res.corrected;
        // A step whose undamped promise is already below the stop's is a
        // polish: stretching it gains less than ftol and moves the result
        // away from the last Jacobian, which the caller's identifiability
        // analysis reuses when the result is close to it.
        if (!(promised <= small_promise)) {
          StretchStep(residuals, z, r, z_ref, o, &z_new, &r_trial, &new_cost, &r_step, &res);
        }
        step_norm = (z_new - z).cwiseAbs().maxCoeff();
        if (!on_secant && jacobian_cost > 1 && step_norm > o.xtol &&
            step_norm <= o.secant_max_step) {
          secant.Set(jac, z_new - z, r, r_trial);
        }
        z = z_new;
        r.swap(r_trial);
        accepted = true;
        // Trust the Gauss–Newton model quickly again after a success: near
        // the optimum its steps are the fast ones.
        lambda = std::max(lambda / 10.0, 1e-9);
        break;
      }
      lambda *= 4.0;
    }
    if (on_secant) secant.active = false;
    if (!accepted && on_secant) {
      // The secant update misled the steps: a Jacobian here decides.
      lambda = lambda_at_start;
      continue;
    }
    if (!accepted) {
      // The smoothed model found no descent of the true objective: sharpen
      // it (continuation on the weight floor) before giving up.
      if (floor_rel > 1e-6) {
        floor_rel *= 0.1;
        lambda = 1e-3;
        continue;
      }
      res.converged = true;
      res.message = "no further descent (damping " + std::to_string(lambda) + ")";
      break;
    }
    const double decrease = cost - new_cost;
    gain_per_promise = promised > 0.0 ? std::max(decrease / promised, 1.0)
                                      : std::numeric_limits<double>::infinity();
    cost = new_cost;
    if (step_norm <= o.xtol && floor_rel > 1e-6) {  // stalled on the smoothing
      floor_rel *= 0.1;
      lambda = 1e-3;
      continue;
    }
    const bool small_decrease = SmallDecreaseStops(decrease, cost, promised, o, &small_in_a_row);
    if (small_decrease || step_norm <= o.xtol) {
      res.converged = true;
      res.message = small_decrease ? "relative decrease below ftol" : "step below xtol";
      break;
    }
  }
  if (res.message.empty()) res.message = "iteration limit reached";
  res.z = z;
  res.final_cost = cost;
  if (have_jac) {
    res.jacobian = std::move(jac);
    res.jacobian_distance = (z - z_jac).cwiseAbs().maxCoeff();
    res.weights = std::move(w);
  }
  return res;
}

}  // namespace pvtwin

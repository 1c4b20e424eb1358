#include <sstream>
#include <utility>
#include <vector>

#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

std::string PValue(double p) {
  std::ostringstream s;
  s.precision(2);
  s << p;
  return s.str();
}

bool PreparePart(const Series& s, const Plant& plant, const ModelSpec& spec,
                 std::int64_t data_start_s, const std::vector<Cleaning>& cleanings, Part* part,
                 std::string* error) {
  if (!PrepareDrivers(s, plant, spec, &part->drivers, error)) return false;
  Drivers& d = part->drivers;
  SetCleanings(cleanings, &d);
  if (d.days_since_clean.size() == d.size()) {
    for (std::size_t i = 0; i < d.size(); ++i) {
      d.days_since_clean[i] = static_cast<double>(d.time_s[i] - data_start_s) / 86400.0;
    }
  }
  part->meas = MakeMeasurements(s, part->drivers);
  return true;
}

Score ScoreHeldout(const Part& heldout, const ParamVector& params, const Units& units,
                   double area_m2) {
  SimOutputs sim;
  Simulate(heldout.drivers, params, &sim);
  return ScoreSim(heldout, std::move(sim), units, area_m2);
}

Score ScoreModel(const Split& split, const Part& heldout, const ParamVector& params,
                 const std::vector<ParamVector>& fold_params, const Units& units, double area_m2) {
  if (fold_params.empty()) return ScoreHeldout(heldout, params, units, area_m2);
  // Every fold's model runs over all days (its states pass through the
  // other days as they would in operation); each row is taken from the
  // model of its own fold.
  SimOutputs all;
  SimOutputs fold;
  for (std::size_t d = 0; d < fold_params.size(); ++d) {
    Simulate(heldout.drivers, fold_params[d], d == 0 ? &all : &fold);
    if (d == 0) continue;
    for (std::size_t i = 0; i < split.fold_of_row.size() && i < all.p_el_w.size(); ++i) {
      if (split.fold_of_row[i] != static_cast<int>(d)) continue;
      for (std::vector<double> SimOutputs::*out :
           {&SimOutputs::p_el_w, &SimOutputs::q_th_w, &SimOutputs::t_pv_c, &SimOutputs::t_coll_c,
            &SimOutputs::t_out_c}) {
        if (i < (all.*out).size() && i < (fold.*out).size()) (all.*out)[i] = (fold.*out)[i];
      }
    }
  }
  return ScoreSim(heldout, std::move(all), units, area_m2);
}

bool CrossFitted(const DiagnosisOptions& options) {
  return options.reference_params.has_value() && options.train_days == 0 &&
         options.heldout_days == 0;
}

Measurements WithoutFold(const Measurements& m, const Split& split, int fold) {
  Measurements out = m;
  std::erase_if(out.rows, [&split, fold](std::uint32_t i) {
    return i < split.fold_of_row.size() && split.fold_of_row[i] == fold;
  });
  return out;
}

Score ScoreSim(const Part& heldout, SimOutputs sim, const Units& units, double area_m2) {
  Score score;
  score.sim = std::move(sim);
  score.errors = ComputeErrors(heldout.meas, score.sim, area_m2);
  const auto n_units = static_cast<std::size_t>(units.count);
  std::vector<double>& sum = score.unit_loss_w;
  std::vector<double>& rows = score.unit_rows;
  sum.assign(n_units, 0.0);
  rows.assign(n_units, 0.0);
  score.unit_loss_p_el_w.assign(n_units, 0.0);
  score.unit_loss_q_th_w.assign(n_units, 0.0);
  for (std::uint32_t i : heldout.meas.rows) {
    const int u = units.unit_of_row[i];
    if (u < 0) continue;
    const auto k = static_cast<std::size_t>(u);
    const double lp = std::fabs(score.sim.p_el_w[i] - heldout.meas.p_el_w[i]);
    const double lq = std::fabs(score.sim.q_th_w[i] - heldout.meas.q_th_w[i]);
    score.unit_loss_p_el_w[k] += lp;
    score.unit_loss_q_th_w[k] += lq;
    sum[k] += lp + lq;
    rows[k] += 1.0;
  }
  score.loss_p_el_w.assign(heldout.meas.size(), kNaN);
  score.loss_q_th_w.assign(heldout.meas.size(), kNaN);
  score.loss_w.assign(heldout.meas.size(), kNaN);
  for (std::uint32_t i : heldout.meas.rows) {
    score.loss_p_el_w[i] = std::fabs(score.sim.p_el_w[i] - heldout.meas.p_el_w[i]);
    score.loss_q_th_w[i] = std::fabs(score.sim.q_th_w[i] - heldout.meas.q_th_w[i]);
    score.loss_w[i] = score.loss_p_el_w[i] + score.loss_q_th_w[i];
    score.bias_p_el_w += score.sim.p_el_w[i] - heldout.meas.p_el_w[i];
    score.bias_q_th_w += score.sim.q_th_w[i] - heldout.meas.q_th_w[i];
  }
  const double n_rows = static_cast<double>(std::max<std::size_t>(1, heldout.meas.rows.size()));
  score.bias_p_el_w /= n_rows;
  score.bias_q_th_w /= n_rows;
  score.unit_objective_w_m2.assign(static_cast<std::size_t>(units.count), kNaN);
  for (std::size_t k = 0; k < sum.size(); ++k) {
    if (rows[k] > 0.0) score.unit_objective_w_m2[k] = sum[k] / rows[k] / area_m2;
  }
  return score;
}

double MaeSumW(const ErrorMetrics& e) { return e.mae_p_el_w + e.mae_q_th_w; }

const std::vector<double>& LossOf(const Score& s, Loss which) {
  return which == Loss::kPEl ? s.loss_p_el_w : which == Loss::kQTh ? s.loss_q_th_w : s.loss_w;
}

Loss SelectionLoss(const DiagnosisOptions& options) {
  switch (options.selection_outputs) {
    case SelectionOutputs::kPEl:
      return Loss::kPEl;
    case SelectionOutputs::kQTh:
      return Loss::kQTh;
    case SelectionOutputs::kBoth:
      break;
  }
  return Loss::kSum;
}

double SelectionObjectiveW(const Score& score, const std::vector<std::uint8_t>& inside,
                           Loss which) {
  const std::vector<double>& loss = LossOf(score, which);
  double loss_w = 0.0, rows = 0.0;
  for (std::size_t i = 0; i < loss.size(); ++i) {
    if (!std::isfinite(loss[i]) || (!inside.empty() && inside[i] == 0)) continue;
    loss_w += loss[i];
    rows += 1.0;
  }
  return rows > 0.0 ? loss_w / rows : kNaN;
}

PairedTest CompareUnits(const Score& before, const Score& after) {
  std::vector<double> b, a;
  for (std::size_t k = 0; k < before.unit_objective_w_m2.size(); ++k) {
    const double x = before.unit_objective_w_m2[k], y = after.unit_objective_w_m2[k];
    if (std::isfinite(x) && std::isfinite(y)) {
      b.push_back(x);
      a.push_back(y);
    }
  }
  return OneSidedPairedTest(b, a);
}

LossDifferenceTest CompareLosses(const Score& before, const Score& after, const Part& heldout,
                                 double bandwidth_s, Loss which) {
  return OneSidedLossDifferenceTest(LossOf(before, which), LossOf(after, which),
                                    heldout.drivers.time_s, bandwidth_s);
}

std::vector<double> Residual(const Measurements& m, const std::vector<double>& pred,
                             const std::vector<double>& meas) {
  std::vector<double> r(m.size(), kNaN);
  for (std::uint32_t i : m.rows) r[i] = pred[i] - meas[i];
  return r;
}

}  // namespace pvtwin::diagnosis_stages

#include "core/diagnosis/diagnosis.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <sstream>
#include <thread>

#include "core/common/calendar.h"
#include "core/common/text.h"
#include "core/data/resample.h"
#include "core/diagnosis/stages.h"

namespace pvtwin {

IdentOptions DiagnosisIdentOptions() {
  IdentOptions o;
  o.optimizer.ftol_rel = 1e-4;
  return o;
}

bool DiagnosisOptions::IsValid(std::string* why) const {
  std::ostringstream out;
  if (train_days < 0) out << "train_days = " << train_days << ": must be ≥ 0 (0 = automatic); ";
  if (heldout_days < 0)
    out << "heldout_days = " << heldout_days << ": must be ≥ 0 (0 = the rest); ";
  if (step_s != 0.0 &&
      !(step_s >= 1.0 && step_s == std::floor(step_s) && std::fmod(86400.0, step_s) == 0.0)) {
    out << "step_s = " << step_s << ": must be 0 or whole seconds dividing 86400; ";
  }
  std::string ident_why;
  if (!ident.IsValid(&ident_why)) out << "ident: " << ident_why << "; ";
  if (!(alpha > 0.0 && alpha < 1.0)) out << "alpha = " << alpha << ": must be in (0, 1); ";
  if (!(loss_test_bandwidth_s >= 0.0 && loss_test_bandwidth_s <= 86400.0)) {
    out << "loss_test_bandwidth_s = " << loss_test_bandwidth_s << ": must be in [0, 86400]; ";
  }
  if (!(extrapolation_share > 0.0 && extrapolation_share <= 1.0)) {
    out << "extrapolation_share = " << extrapolation_share << ": must be in (0, 1]; ";
  }
  if (!(min_shrink_pct >= 0.0 && min_shrink_pct < 100.0)) {
    out << "min_shrink_pct = " << min_shrink_pct << ": must be in [0, 100); ";
  }
  if (min_test_units < 2) out << "min_test_units = " << min_test_units << ": must be ≥ 2; ";
  if (!(min_confidence > 0.5 && min_confidence < 1.0)) {
    out << "min_confidence = " << min_confidence << ": must be in (0.5, 1); ";
  }
  if (bootstrap_resamples < 100) {
    out << "bootstrap_resamples = " << bootstrap_resamples << ": must be ≥ 100; ";
  }
  if (sensor_step_min_rows < 1) {
    out << "sensor_step_min_rows = " << sensor_step_min_rows << ": must be ≥ 1; ";
  }
  if (!(min_temperature_offset_k >= 0.0)) {
    out << "min_temperature_offset_k = " << min_temperature_offset_k << ": must be ≥ 0; ";
  }
  if (!(sensor_night_g_w_m2 >= 0.0)) {
    out << "sensor_night_g_w_m2 = " << sensor_night_g_w_m2 << ": must be ≥ 0; ";
  }
  if (!(min_flow_scale_error >= 0.0 && min_flow_scale_error < 1.0)) {
    out << "min_flow_scale_error = " << min_flow_scale_error << ": must be in [0, 1); ";
  }
  if (max_ladder_steps < 1) out << "max_ladder_steps = " << max_ladder_steps << ": must be ≥ 1; ";
  if (!(unknown_noise_ratio > 1.0)) {
    out << "unknown_noise_ratio = " << unknown_noise_ratio << ": must be > 1; ";
  }
  if (reference_params.has_value()) {
    for (std::size_t i = 0; i < kNumParams; ++i) {
      if (!std::isfinite((*reference_params)[i])) {
        out << "reference_params: " << Info(static_cast<Param>(i)).name << " is not finite; ";
      }
    }
  }
  if (reference_days != nullptr && !reference_params.has_value()) {
    out << "reference_days: only with reference_params (the days they were fitted on); ";
  }
  if (reference_days != nullptr && reference_days->size() < 2) {
    out << "reference_days: " << reference_days->size() << " rows, must be at least 2; ";
  }
  const std::vector<std::string> names = EffectNames();
  for (const std::string& e : effects) {
    if (std::find(names.begin(), names.end(), e) == names.end()) {
      out << "effects = " << e << ": not an effect of the vocabulary; ";
    }
  }
  std::string where_why;
  if (!where.IsValid(&where_why)) out << "where: " << where_why << "; ";
  if (threads < 0) out << "threads = " << threads << ": must be ≥ 0; ";
  const std::string text = out.str();
  if (why != nullptr) *why = text.empty() ? "" : text.substr(0, text.size() - 2);
  return text.empty();
}

std::string_view SelectionOutputsName(SelectionOutputs o) {
  switch (o) {
    case SelectionOutputs::kPEl:
      return "p_el";
    case SelectionOutputs::kQTh:
      return "q_th";
    case SelectionOutputs::kBoth:
      break;
  }
  return "both";
}

bool ParseSelectionOutputs(std::string_view text, SelectionOutputs* out) {
  for (SelectionOutputs o :
       {SelectionOutputs::kBoth, SelectionOutputs::kPEl, SelectionOutputs::kQTh}) {
    if (text == SelectionOutputsName(o)) {
      *out = o;
      return true;
    }
  }
  return false;
}

namespace {

bool DiagnoseOnce(const Series& data_in, const Plant& plant, const ModelSpec& base,
                  const DiagnosisOptions& options, bool recheck_after_sensor_onset,
                  DiagnosisResult* result, std::string* error,
                  const std::function<void(const std::string&)>& progress_in);

// A named sensor fault that moves the measured Q_u from a held-out day on
// (offset_step, scale) makes every model that predicts less heat look
// better on the days after it. The effect the ladder accepted first must
// then also be the first one chosen on the held-out days before that onset
// (the same training days); otherwise its evidence lies on the faulty days
// and it is not named. Returns the sentence for the report's notes when the
// effect does not hold; "" when it does or nothing is to be checked. The
// second diagnosis's fits are added to r->identifications.
std::string EffectWithoutFaultyDays(const Series& data, const Plant& plant, const ModelSpec& base,
                                    const DiagnosisOptions& options,
                                    const diagnosis_stages::Split& split,
                                    const std::vector<SensorFinding>& steps, DiagnosisResult* r) {
  if (r->ladder.size() < 2) return "";
  const std::int64_t heldout_start_s =
      split.day_starts[static_cast<std::size_t>(split.FirstHeldoutDay())];
  const SensorFinding* first = nullptr;
  for (const SensorFinding& f : steps) {
    if ((f.kind != "offset_step" && f.kind != "scale") || f.from_s <= heldout_start_s) continue;
    if (first == nullptr || f.from_s < first->from_s) first = &f;
  }
  if (first == nullptr) return "";
  int clean_days = 0;
  for (std::int64_t d : split.day_starts) {
    clean_days += d >= heldout_start_s && d < first->from_s ? 1 : 0;
  }
  const std::string effect = r->ladder[1].added;
  std::string outcome = "no held-out day lies before it";
  if (clean_days > 0) {
    DiagnosisOptions before = options;
    if (split.folds == 0) {  // the same training days; else each day before it in turn
      before.train_days = split.train_days;
      before.heldout_days = clean_days;
    }
    DiagnosisResult clean;
    std::string why;
    const bool ok = DiagnoseOnce(data.Slice(0, data.RowAtOrAfter(first->from_s)), plant, base,
                                 before, false, &clean, &why, nullptr);
    r->identifications += clean.identifications;
    if (!ok) {
      outcome = "the days before it cannot be diagnosed (" + why + ")";
    } else if (clean.ladder.size() > 1 && clean.ladder[1].added == effect) {
      return "";
    } else {
      outcome = "on the " + std::to_string(clean_days) +
                " held-out day(s) before it the verdict is " +
                (clean.verdict.empty() ? "none" : clean.verdict);
    }
  }
  return effect + " was chosen on held-out days that include those from " + first->from +
         ", when the named " + first->channel + " " + first->kind +
         " begins (it moves the measured Q_u); " + outcome +
         ": its evidence lies on the faulty days, so it is not named";
}

}  // namespace

bool Diagnose(const Series& data_in, const Plant& plant, const ModelSpec& base,
              const DiagnosisOptions& options, DiagnosisResult* result, std::string* error,
              const std::function<void(const std::string&)>& progress_in) {
  return DiagnoseOnce(data_in, plant, base, options, true, result, error, progress_in);
}

namespace {

bool DiagnoseOnce(const Series& data_in, const Plant& plant, const ModelSpec& base,
                  const DiagnosisOptions& options, bool recheck_after_sensor_onset,
                  DiagnosisResult* result, std::string* error,
                  const std::function<void(const std::string&)>& progress_in) {
  namespace st = diagnosis_stages;
  const auto t0 = std::chrono::steady_clock::now();
  std::mutex progress_mutex;
  auto progress = [&](const std::string& line) {
    if (!progress_in) return;
    std::lock_guard<std::mutex> lock(progress_mutex);
    progress_in(line);
  };
  if (!options.IsValid(error)) return false;
  if (data_in.size() < 2) {
    *error = "the data have fewer than 2 rows";
    return false;
  }
  Series data;
  if (options.step_s > 0.0 && options.step_s != data_in.step_s) {
    if (!Resample(data_in, options.step_s, &data, error)) return false;
  } else {
    data = data_in;
  }
  DiagnosisResult r;
  r.base_variant = base.Name();
  r.step_s = data.step_s;

  st::Split split;
  if (!st::SplitDays(data, plant, options, &split, error)) return false;
  st::BaseFit base_fit;
  if (!st::FitBase(split, plant, base, options, progress, &base_fit, &r, error)) return false;
  const st::BaseResiduals residuals = st::LocaliseBaseGap(split, base_fit, plant, options, &r);
  r.extrapolation = st::FindExtrapolation(base_fit, options);
  r.sensors = st::CheckSensors(data, plant);
  if (!base_fit.train.drivers.sky_note.empty()) r.notes.push_back(base_fit.train.drivers.sky_note);
  r.sky_used = base_fit.train.drivers.sky_used;
  if (!split.cleanings.empty()) {
    std::string days;
    for (const Cleaning& c : split.cleanings) {
      days += (days.empty() ? "" : ", ") + SolarDate(c.time_s, split.offset_s) + " (+" +
              FixedDecimals(100.0 * c.recovered, 1) + " %)";
    }
    r.notes.push_back(
        "cleanings the data show (the daily performance index recovers and stays "
        "up; soiling's loss drops by the recovery): " +
        days);
  }

  st::ReferenceDays reference_days;
  if (options.reference_days != nullptr &&
      !st::PrepareReferenceDays(options, data.step_s, plant, base, &reference_days, error)) {
    return false;
  }

  if (options.selection_outputs != SelectionOutputs::kBoth) {
    r.notes.push_back(std::string("the model selection compares the held-out MAE of ") +
                      (options.selection_outputs == SelectionOutputs::kPEl ? "P_el" : "Q_u") +
                      " only at the first step, the output whose change is diagnosed (an "
                      "effect that leaves it as it was explains none of the change), and MAE "
                      "P_el + Q_u at later steps (the rest of the gap, which no alarm dated); "
                      "the shrinks reported are those of MAE P_el + Q_u");
  }

  st::TrialInputs trials;
  if (options.reference_days != nullptr) trials.reference = &reference_days;
  trials.data = &data;
  trials.split = &split;
  trials.plant = &plant;
  trials.options = &options;
  trials.base = &base_fit;
  trials.residuals = &residuals;
  trials.controls = st::EvidenceControls(base_fit.heldout.drivers);
  trials.threads = options.threads > 0
                       ? options.threads
                       : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  trials.test_unit = r.test_unit;
  trials.progress = progress;
  trials.extrapolation = &r.extrapolation;
  st::LadderModel final_model = st::RunLadder(trials, base, &r);
  // The residual sensor checks read the residuals of the final model: a
  // base model that lacks a large effect leaves day-to-day structure that a
  // step can fit (final-check seed 31, other-form wind in October: a false
  // t_out_c step with the base 1N1Cr fitted on all days).
  std::vector<SensorFinding> steps =
      st::FindResidualSensorFaults(data, split, plant, final_model.spec, final_model.params,
                                   options, progress, &r.identifications);
  const std::string faulty =
      recheck_after_sensor_onset
          ? EffectWithoutFaultyDays(data, plant, base, options, split, steps, &r)
          : std::string();
  if (!faulty.empty()) {
    progress("sensor re-check: " + faulty);
    r.notes.push_back(faulty);
    r.ladder.resize(1);
    r.candidates.clear();
    r.separation.clear();
    for (EffectTrial& t : r.effects) t.accepted_at_step = 0;
    r.final_variant = base.Name();
    final_model = st::LadderModel{base, base_fit.params, base_fit.score, {}};
  }
  r.sensors.insert(r.sensors.begin(), std::make_move_iterator(steps.begin()),
                   std::make_move_iterator(steps.end()));

  if (!st::EstimateNoiseFloor(split, plant, final_model, &r, error)) return false;
  st::BuildReportModel(split, base_fit, residuals, final_model, plant.area_m2, &r);
  st::DecideVerdict(options, &r);
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  *result = std::move(r);
  return true;
}

}  // namespace

GapBias BaseModelBias(const DiagnosisResult& r) {
  const double nan = std::nan("");
  auto mean_and_share = [nan](const std::vector<double>& predicted,
                              const std::vector<double>& measured, double* bias, double* share) {
    double sum = 0.0, sum_abs = 0.0;
    int n = 0;
    for (std::size_t i = 0; i < predicted.size() && i < measured.size(); ++i) {
      if (!std::isfinite(predicted[i]) || !std::isfinite(measured[i])) continue;
      sum += predicted[i] - measured[i];
      sum_abs += std::fabs(predicted[i] - measured[i]);
      ++n;
    }
    *bias = n > 0 ? sum / n : nan;
    *share = sum_abs > 0.0 ? std::fabs(sum) / sum_abs : nan;
  };
  GapBias b;
  mean_and_share(r.trace.p_el_base_w, r.trace.p_el_meas_w, &b.p_el_w, &b.share_p_el);
  mean_and_share(r.trace.q_th_base_w, r.trace.q_th_meas_w, &b.q_th_w, &b.share_q_th);
  return b;
}

}  // namespace pvtwin

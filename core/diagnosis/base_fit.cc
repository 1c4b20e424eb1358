#include <algorithm>
#include <map>

#include "core/common/calendar.h"
#include "core/data/resample.h"
#include "core/diagnosis/stages.h"

namespace pvtwin::diagnosis_stages {

bool FitBase(const Split& split, const Plant& plant, const ModelSpec& base,
             const DiagnosisOptions& options, const Progress& progress, BaseFit* fit,
             DiagnosisResult* result, std::string* error) {
  DiagnosisResult& r = *result;
  const Series& train_series = split.train_series;
  const Series& heldout_series = split.heldout_series;
  const std::int64_t data_start_s = split.data_start_s;
  const std::int64_t offset_s = split.offset_s;
  const int train_days = split.train_days;
  const int heldout_days = split.heldout_days;
  Part& base_train = fit->train;
  Part& base_heldout = fit->heldout;
  Units& units = fit->units;
  if (!PreparePart(train_series, plant, base, data_start_s, split.cleanings, &base_train, error) ||
      !PreparePart(heldout_series, plant, base, data_start_s, split.cleanings, &base_heldout,
                   error)) {
    return false;
  }
  const std::size_t min_rows = static_cast<std::size_t>(std::max(options.ident.min_rows, 1));
  if (base_train.meas.rows.size() < min_rows || base_heldout.meas.rows.size() < min_rows) {
    *error = "too little data: " + std::to_string(base_train.meas.rows.size()) +
             " objective rows in the training days and " +
             std::to_string(base_heldout.meas.rows.size()) + " in the held-out days (need " +
             std::to_string(min_rows) + " each)";
    return false;
  }
  // Test units: held-out days, or hours when there are too few days.
  r.low_confidence = heldout_days < options.min_test_units;
  r.test_unit = r.low_confidence ? "hour" : "day";
  {
    std::map<std::int64_t, int> index;
    const std::int64_t unit_s = r.low_confidence ? 3600 : kSecondsPerDay;
    units.unit_of_row.assign(heldout_series.size(), -1);
    for (std::uint32_t i : base_heldout.meas.rows) {
      const std::int64_t t = heldout_series.time_s[i];
      const std::int64_t key =
          r.low_confidence ? (t - offset_s) / unit_s : SolarDayStartS(t, offset_s);
      auto [it, inserted] = index.emplace(key, units.count);
      if (inserted) ++units.count;
      units.unit_of_row[i] = it->second;
    }
  }
  if (r.low_confidence) {
    r.notes.push_back("only " + std::to_string(heldout_days) +
                      " held-out day(s): improvements are tested over one-hour blocks, which share "
                      "the weather of their day, so a significant result is weaker evidence than "
                      "one over " +
                      std::to_string(options.min_test_units) + "+ days");
  }
  if (split.folds > 0) {
    r.notes.push_back("each of the " + std::to_string(split.folds) +
                      " days is held out in turn: a candidate's own parameters are fitted on the "
                      "other " +
                      std::to_string(split.folds - 1) +
                      " days and it is scored on that day, so that every day is a held-out day");
  }
  progress("diagnosis: " +
           (split.folds > 0 ? "each of " + std::to_string(heldout_days) + " days held out in turn"
                            : std::to_string(train_days) + " training days, " +
                                  std::to_string(heldout_days) + " held-out days") +
           ", step " + FixedDecimals(r.step_s, 0) + " s; " +
           (options.reference_params ? "the base model " + r.base_variant +
                                           " keeps the parameters of " + options.reference_name
                                     : "fitting the base model " + r.base_variant));
  IdentSummary base_fit;
  if (options.reference_params) {
    // The plant before a change: nothing of the base is fitted on the days
    // since (DiagnosisOptions::reference_params).
    base_fit.ok = true;
    base_fit.params = *options.reference_params;
    r.notes.push_back("the base model " + r.base_variant + " keeps the parameters of " +
                      options.reference_name +
                      " (the plant before the change); each candidate fits only the parameters "
                      "its effect adds: which effect explains what changed" +
                      (options.reference_days != nullptr
                           ? "; those parameters are also fitted on the days of the reference, "
                             "and a candidate counts with its gain beyond what it gains with "
                             "them (an effect the plant had before explains no change)"
                           : ""));
  } else {
    RangedFit ranged =
        IdentifyInRanges(base_train.drivers, base_train.meas, StartParams(plant), options);
    base_fit = std::move(ranged.fit);
    r.identifications = ranged.refitted.empty() ? 1 : 2;
    r.base_refitted = ranged.refitted;
    for (const RefittedParam& refit : ranged.refitted) {
      r.notes.push_back("base model " + r.base_variant + ": " + RefittedSentence(refit));
    }
  }
  if (!base_fit.ok) {
    *error = "identification of the base model " + r.base_variant +
             " failed: " + base_fit.failure_reason;
    return false;
  }
  const double area_m2 = plant.area_m2;
  Simulate(base_train.drivers, base_fit.params, &fit->train_sim);
  fit->score = ScoreHeldout(base_heldout, base_fit.params, units, area_m2);
  const Score& base_score = fit->score;
  r.gap = base_score.errors;
  progress("base " + r.base_variant + ": held-out MAE P_el " + FixedDecimals(r.gap.mae_p_el_w, 2) +
           " W, Q_u " + FixedDecimals(r.gap.mae_q_th_w, 2) + " W (" +
           FixedDecimals(base_fit.runtime_s, 2) + " s)");
  {
    LadderStep step;
    step.variant = r.base_variant;
    step.heldout = base_score.errors;
    step.heldout_mae_w = MaeSumW(base_score.errors);
    step.objective_w_m2 = base_score.errors.objective_w_m2();
    step.params = base_fit.params;
    r.ladder.push_back(step);
  }
  fit->params = base_fit.params;
  return true;
}

bool PrepareReferenceDays(const DiagnosisOptions& options, double step_s, const Plant& plant,
                          const ModelSpec& base, ReferenceDays* out, std::string* error) {
  const Series& given = *options.reference_days;
  std::string why;
  if (given.step_s == step_s) {
    out->series = given;
  } else if (!Resample(given, step_s, &out->series, &why)) {
    *error = "reference_days: " + why;
    return false;
  }
  if (out->series.size() == 0) {
    *error = "reference_days: no rows at the step of " + FixedDecimals(step_s, 0) + " s";
    return false;
  }
  // The days-since-cleaning clock counts from their own first row.
  if (!PreparePart(out->series, plant, base, out->series.time_s.front(), {}, &out->base, &why)) {
    *error = "reference_days: " + (why.empty() ? "cannot be prepared" : why);
    return false;
  }
  Simulate(out->base.drivers, *options.reference_params, &out->base_sim);
  return true;
}

}  // namespace pvtwin::diagnosis_stages

#include "io/report/diagnosis_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/common/params.h"
#include "io/files/params_json.h"
#include "io/report/svg_plot.h"

namespace pvtwin {

namespace {

using Json = nlohmann::ordered_json;

Json Number(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

// Range bound: ±infinity as null (JSON has no infinity).
Json Range(double lo, double hi) { return Json::array({Number(lo), Number(hi)}); }

Json RegionJson(const GapRegion& g) {
  Json j;
  j["driver"] = g.driver;
  j["range"] = Range(g.lower, g.upper);
  j["share_of_abs_error"] = Number(g.share_of_abs_error);
  j["output"] = g.output;
  j["share_of_rows"] = Number(g.share_of_rows);
  j["bias_w"] = Number(g.bias_w);
  j["mae_w"] = Number(g.mae_w);
  j["rows"] = g.rows;
  j["z"] = Number(g.z);
  if (!g.label.empty()) j["label"] = g.label;
  if (!g.driver2.empty()) {
    j["and"] = Json{{"driver", g.driver2}, {"range", Range(g.lower2, g.upper2)}};
  }
  return j;
}

std::string Fixed(double x, int digits) {
  if (!std::isfinite(x)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, x);
  return buf;
}

std::string RangeText(double lo, double hi) {
  auto b = [](double v) {
    if (std::isinf(v)) return std::string(v < 0 ? "−∞" : "∞");
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return std::string(buf);
  };
  return "[" + b(lo) + ", " + b(hi) + ")";
}

std::string RegionText(const GapRegion& g) {
  std::string s = g.driver + " " + RangeText(g.lower, g.upper);
  if (!g.label.empty()) s = g.driver + " " + g.label;
  if (!g.driver2.empty()) s += " × " + g.driver2 + " " + RangeText(g.lower2, g.upper2);
  return s;
}

// Mean |residual| over a grid of two trace variables.
SvgHeatmap Heat(const std::vector<double>& xv, const std::vector<double>& yv,
                const std::vector<double>& abs_r, std::vector<double> x_edges,
                std::vector<double> y_edges) {
  SvgHeatmap m;
  m.x_edges = std::move(x_edges);
  m.y_edges = std::move(y_edges);
  const std::size_t nx = m.x_edges.size() - 1, ny = m.y_edges.size() - 1;
  std::vector<double> sum(nx * ny, 0.0), cnt(nx * ny, 0.0);
  for (std::size_t i = 0; i < abs_r.size(); ++i) {
    if (!std::isfinite(xv[i]) || !std::isfinite(yv[i]) || !std::isfinite(abs_r[i])) continue;
    const auto ix =
        std::upper_bound(m.x_edges.begin(), m.x_edges.end(), xv[i]) - m.x_edges.begin() - 1;
    const auto iy =
        std::upper_bound(m.y_edges.begin(), m.y_edges.end(), yv[i]) - m.y_edges.begin() - 1;
    if (ix < 0 || iy < 0 || static_cast<std::size_t>(ix) >= nx ||
        static_cast<std::size_t>(iy) >= ny)
      continue;
    const std::size_t k = static_cast<std::size_t>(iy) * nx + static_cast<std::size_t>(ix);
    sum[k] += abs_r[i];
    cnt[k] += 1.0;
  }
  m.values.assign(nx * ny, std::nan(""));
  for (std::size_t k = 0; k < nx * ny; ++k) {
    if (cnt[k] >= 3) m.values[k] = sum[k] / cnt[k];
  }
  return m;
}

std::vector<double> Edges(double lo, double hi, double step) {
  std::vector<double> e;
  for (double v = lo; v <= hi + 1e-9; v += step) e.push_back(v);
  return e;
}

// Parameters a fit left at a Table 3 bound and re-fitted in their physical
// range (core/common/physical_ranges.h).
Json RefittedJson(const std::vector<RefittedParam>& refitted) {
  Json out = Json::array();
  for (const RefittedParam& f : refitted) {
    out.push_back(Json{{"param", std::string(Info(f.param).name)},
                       {"table3_bound", Number(f.table_bound)},
                       {"lower", Number(f.lower)},
                       {"upper", Number(f.upper)},
                       {"value", Number(f.value)},
                       {"used", f.used}});
  }
  return out;
}

const char* SkyName(SkyUsed sky) {
  switch (sky) {
    case SkyUsed::kMeasured:
      return "measured";
    case SkyUsed::kAirTemperature:
      return "air_temperature";
    case SkyUsed::kDewPoint:
      return "dew_point";
  }
  return "measured";
}

// One entry of report.json's `effects`.
Json EffectJson(const EffectTrial& t) {
  Json e;
  e["name"] = t.name;
  e["significant"] = t.significant;
  e["confidence"] = Number(t.fit_ok ? t.confidence : std::nan(""));
  e["confidence_beats"] = Number(t.fit_ok ? t.confidence_beats : std::nan(""));
  if (t.sensor_fault) e["sensor_fault"] = true;
  e["shrink_pct"] = Number(t.fit_ok ? t.shrink_pct : std::nan(""));
  if (t.fit_ok && std::isfinite(t.shrink_before_change_pct)) {
    e["shrink_before_change_pct"] = Number(t.shrink_before_change_pct);
  }
  e["heldout_mae_before_w"] = Number(t.heldout_mae_before_w);
  e["heldout_mae_after_w"] = Number(t.fit_ok ? t.heldout_mae_after_w : std::nan(""));
  e["evidence"] = t.evidence;
  e["refitted"] = RefittedJson(t.refitted);
  e["variant"] = t.variant;
  if (!t.form.empty()) e["form"] = t.form;
  if (t.forms.size() > 1) {
    Json forms = Json::array();
    for (const EffectTrial::FormResult& f : t.forms) {
      forms.push_back(Json{{"form", f.form},
                           {"variant", f.variant},
                           {"heldout_mae_after_w", Number(f.heldout_mae_after_w)}});
    }
    e["forms"] = forms;
  }
  e["tested_against"] = t.tested_against;
  e["accepted_at_step"] = t.accepted_at_step;
  e["p_value"] = Number(t.test.wilcoxon_p);
  e["sign_test_p"] = Number(t.test.sign_p);
  e["t_stat"] = Number(t.test.t_stat);
  e["units_better"] = t.test.positives;
  e["units"] = t.test.pairs;
  e["evidence_r"] = Number(t.evidence_corr.r);
  e["evidence_z"] = Number(t.evidence_corr.z);
  e["evidence_output"] = t.evidence_output;
  if (std::isfinite(t.sensor_estimate)) {
    e["irradiance_bias_k"] = Number(t.sensor_estimate);
    e["irradiance_bias_p"] = Number(t.sensor_p);
  }
  if (t.fit_ok) {
    e["heldout_test"] = Json{{"kind", "loss_difference"},
                             {"p", Number(t.heldout_test.p)},
                             {"z", Number(t.heldout_test.z)},
                             {"rows", t.heldout_test.rows},
                             {"mean_loss_difference_w", Number(t.heldout_test.mean_difference)},
                             {"bandwidth_rows", t.heldout_test.bandwidth_rows}};
    e["mae_p_el_after_w"] = Number(t.mae_p_el_after_w);
    e["mae_q_th_after_w"] = Number(t.mae_q_th_after_w);
    e["days_better"] = t.days_improved;
    Json params = Json::object();
    for (const ParamEstimate& p : t.estimates) {
      params[std::string(Info(p.param).name)] = Json{{"value", Number(p.value)},
                                                     {"std_error", Number(StdErrorInUnit(p))},
                                                     {"unit", std::string(Info(p.param).unit)}};
    }
    e["params"] = params;
    if (!t.at_bounds.empty()) e["at_bounds"] = t.at_bounds;
    if (!t.signature_check.empty()) e["signature_check"] = t.signature_check;
    if (!t.rejected.empty()) e["rejected"] = t.rejected;
    if (!t.cautions.empty()) e["cautions"] = t.cautions;
  }
  e["explanation"] = t.explanation;
  if (!t.advice.empty()) e["advice"] = t.advice;
  e["fit_ok"] = t.fit_ok;
  if (!t.fit_ok) e["failure"] = t.failure;
  return e;
}

}  // namespace

std::string DiagnosisReportJson(const DiagnosisResult& r) {
  Json j;
  j["base_variant"] = r.base_variant;
  const GapBias bias = BaseModelBias(r);
  j["gap"] = Json{{"mae_p_el_w", Number(r.gap.mae_p_el_w)},
                  {"mae_q_th_w", Number(r.gap.mae_q_th_w)},
                  {"nmae_p_el", Number(r.gap.nmae_p_el)},
                  {"nmae_q_th", Number(r.gap.nmae_q_th)},
                  {"rows", r.gap.rows},
                  {"objective_w_m2", Number(r.gap.objective_w_m2())},
                  {"bias_p_el_w", Number(bias.p_el_w)},
                  {"bias_q_th_w", Number(bias.q_th_w)},
                  {"bias_share_p_el", Number(bias.share_p_el)},
                  {"bias_share_q_th", Number(bias.share_q_th)}};
  Json where = Json::array();
  for (const GapRegion& g : r.where) where.push_back(RegionJson(g));
  j["where"] = where;
  Json effects = Json::array();
  for (const EffectTrial& t : r.effects) effects.push_back(EffectJson(t));
  j["effects"] = effects;
  j["verdict"] = r.verdict;
  if (!r.candidates.empty()) j["candidates"] = r.candidates;
  if (!r.separation.empty()) j["separation"] = r.separation;
  j["verdict_sentence"] = r.verdict_sentence;
  Json extrapolation = Json::array();
  for (const Extrapolation& x : r.extrapolation) {
    extrapolation.push_back(Json{{"driver", x.driver},
                                 {"train_range", {Number(x.train_low), Number(x.train_high)}},
                                 {"heldout_range", {Number(x.heldout_low), Number(x.heldout_high)}},
                                 {"share_outside", Number(x.share_outside)}});
  }
  j["extrapolation"] = extrapolation;
  Json sensors = Json::array();
  for (const SensorFinding& f : r.sensors) {
    sensors.push_back(Json{{"channel", f.channel},
                           {"kind", f.kind},
                           {"rows", f.rows},
                           {"share", Number(f.share)},
                           {"size", Number(f.size)},
                           {"detail", f.detail}});
    if (!f.from.empty()) sensors.back()["from"] = f.from;
  }
  j["sensors"] = sensors;
  j["final_variant"] = r.final_variant;
  Json ladder = Json::array();
  for (const LadderStep& s : r.ladder) {
    ladder.push_back(Json{{"variant", s.variant},
                          {"added", s.added},
                          {"heldout_mae_w", Number(s.heldout_mae_w)},
                          {"mae_p_el_w", Number(s.heldout.mae_p_el_w)},
                          {"mae_q_th_w", Number(s.heldout.mae_q_th_w)},
                          {"objective_w_m2", Number(s.objective_w_m2)},
                          {"shrink_pct", Number(s.shrink_pct)},
                          {"p_value", Number(s.p_value)},
                          {"loss_test_p", Number(s.loss_test_p)}});
  }
  j["ladder"] = ladder;
  j["noise_floor"] = Json{{"mae_p_el_w", Number(r.noise.mae_p_el_w)},
                          {"mae_q_th_w", Number(r.noise.mae_q_th_w)},
                          {"objective_w_m2", Number(r.noise.objective_w_m2)},
                          {"ratio", Number(r.noise.ratio)}};
  j["test_unit"] = r.test_unit;
  j["low_confidence"] = r.low_confidence;
  j["notes"] = r.notes;
  j["base_refitted"] = RefittedJson(r.base_refitted);
  j["sky"] = SkyName(r.sky_used);
  Json skipped = Json::array();
  for (const SkippedEffect& s : r.skipped)
    skipped.push_back(Json{{"name", s.name}, {"why", s.why}});
  j["skipped_effects"] = skipped;
  Json days = Json::array();
  for (const DiagnosisDay& d : r.days) {
    days.push_back(
        Json{{"date", d.date},
             {"start_s", d.start_s},
             {"heldout", d.heldout},
             {"rows", d.rows},
             {"base_objective_w_m2", Number(d.heldout ? d.base_objective_w_m2 : std::nan(""))},
             {"final_objective_w_m2", Number(d.heldout ? d.final_objective_w_m2 : std::nan(""))}});
  }
  j["days"] = days;
  j["step_s"] = Number(r.step_s);
  j["identifications"] = r.identifications;
  j["wall_time_s"] = Number(r.wall_time_s);
  return j.dump(2) + "\n";
}

namespace {

// The HTML report's sections, in the order DiagnosisReportHtml writes them.

// The document head and its style sheet.
void HtmlHead(std::ostream& h, const DiagnosisResult& r) {
  h << "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
    << "<title>pvtwin gap diagnosis: " << XmlEscape(r.base_variant) << "</title>\n<style>"
    << "body{font-family:sans-serif;max-width:1000px;margin:1em auto;color:#222}"
    << "table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #ccc;padding:3px 7px;"
    << "font-size:13px;text-align:right}th{background:#f3f3f3}td.l,th.l{text-align:left}"
    << ".verdict{font-size:1.15em;background:#fff6e0;border-left:5px solid #e0a000;padding:0.6em}"
    << ".sig{font-weight:bold;color:#0a6b0a}.note{color:#a04000}</style></head><body>\n";
}

// The title, the verdict with its advice for the site, and the notes.
void HtmlVerdict(std::ostream& h, const DiagnosisResult& r) {
  h << "<h1>Gap diagnosis of " << XmlEscape(r.base_variant) << "</h1>\n";
  h << "<p class='verdict'><b>Verdict: " << XmlEscape(r.verdict) << ".</b> "
    << XmlEscape(r.verdict_sentence) << "</p>\n";
  for (const EffectTrial& t : r.effects) {
    if (t.name == r.verdict && !t.advice.empty()) {
      h << "<p><b>For the site:</b> " << XmlEscape(t.advice) << "</p>\n";
    }
  }
  for (const std::string& n : r.notes) h << "<p class='note'>" << XmlEscape(n) << "</p>\n";
}

// No training day: each day was held out in turn (against the plant before
// a change), its effects fitted on the other days.
bool EachDayHeldOutInTurn(const DiagnosisResult& r) {
  return !r.days.empty() &&
         std::all_of(r.days.begin(), r.days.end(), [](const DiagnosisDay& d) { return d.heldout; });
}

// Training and held-out days, the base model's held-out error and the noise floor.
void HtmlErrorSummary(std::ostream& h, const DiagnosisResult& r) {
  std::size_t train = 0, heldout = 0;
  for (const DiagnosisDay& d : r.days) (d.heldout ? heldout : train)++;
  if (EachDayHeldOutInTurn(r)) {
    h << "<p>Each of the " << heldout
      << " days held out in turn, its effects fitted on the other days";
  } else {
    h << "<p>Identified on " << train << " training days, scored on " << heldout
      << " held-out days";
  }
  h << " at a " << Fixed(r.step_s, 0) << " s step. Held-out error of the base model: "
    << "MAE P<sub>el</sub> " << Fixed(r.gap.mae_p_el_w, 2) << " W (nMAE "
    << Fixed(100 * r.gap.nmae_p_el, 1) << " %), MAE Q<sub>u</sub> " << Fixed(r.gap.mae_q_th_w, 2)
    << " W (nMAE " << Fixed(100 * r.gap.nmae_q_th, 1) << " %). Sensor noise alone would give about "
    << Fixed(r.noise.mae_p_el_w, 2) << " W and " << Fixed(r.noise.mae_q_th_w, 2)
    << " W; the final model's held-out error is " << Fixed(r.noise.ratio, 1)
    << "× that floor.</p>\n";
}

// The ladder: the base model and each effect accepted on top of it.
void HtmlLadder(std::ostream& h, const DiagnosisResult& r) {
  h << "<h2>Ladder</h2>\n<table><tr><th class='l'>step</th><th class='l'>model</th>"
    << "<th>MAE P<sub>el</sub> W</th><th>MAE Q<sub>u</sub> W</th><th>sum W</th>"
    << "<th>objective W/m²</th><th>shrink %</th><th>loss test p</th></tr>\n";
  for (std::size_t k = 0; k < r.ladder.size(); ++k) {
    const LadderStep& s = r.ladder[k];
    h << "<tr><td class='l'>" << (k == 0 ? "base" : "+" + XmlEscape(s.added))
      << "</td><td class='l'>" << XmlEscape(s.variant) << "</td><td>"
      << Fixed(s.heldout.mae_p_el_w, 2) << "</td><td>" << Fixed(s.heldout.mae_q_th_w, 2)
      << "</td><td>" << Fixed(s.heldout_mae_w, 2) << "</td><td>" << Fixed(s.objective_w_m2, 3)
      << "</td><td>" << (k ? Fixed(s.shrink_pct, 1) : "") << "</td><td>"
      << (k ? Fixed(s.loss_test_p, 4) : "") << "</td></tr>\n";
  }
  h << "</table>\n";
}

// Every effect tried, the ones not tried, and what each means.
void HtmlEffectsTested(std::ostream& h, const DiagnosisResult& r) {
  const bool in_turn = EachDayHeldOutInTurn(r);
  h << "<h2>Effects tested</h2>\n<p>Each effect was added to the model, the model re-identified "
    << (in_turn ? "without each day in turn and scored on that day's "
                : "on the training days and scored on the held-out ")
    << XmlEscape(r.test_unit)
    << "s. Significant = named by the model selection: its confidence, the share of resamples "
    << "of the held-out " << XmlEscape(r.test_unit)
    << "s in which it is the best candidate and beats the model, reaches the threshold; p is the "
    << "one-sided Wilcoxon signed-rank test over " << XmlEscape(r.test_unit)
    << "s, for reference.</p>\n"
    << "<table><tr><th class='l'>effect</th><th class='l'>model</th><th>before W</th>"
    << "<th>after W</th><th>shrink %</th><th>better</th><th>p</th><th>evidence r</th>"
    << "<th class='l'>significant</th></tr>\n";
  for (const EffectTrial& t : r.effects) {
    h << "<tr><td class='l' title='" << XmlEscape(t.explanation) << "'>" << XmlEscape(t.name)
      << "</td><td class='l'>" << XmlEscape(t.variant) << "</td><td>"
      << Fixed(t.heldout_mae_before_w, 2) << "</td><td>"
      << (t.fit_ok ? Fixed(t.heldout_mae_after_w, 2) : "failed") << "</td><td>"
      << (t.fit_ok ? Fixed(t.shrink_pct, 1) : "") << "</td><td>" << t.test.positives << "/"
      << t.test.pairs << "</td><td>" << Fixed(t.test.wilcoxon_p, 4) << "</td><td>"
      << Fixed(t.evidence_corr.r, 2) << "</td><td class='l" << (t.significant ? " sig" : "") << "'>"
      << (t.significant ? "yes" : "no")
      << (t.accepted_at_step ? " (step " + std::to_string(t.accepted_at_step) + ")" : "")
      << "</td></tr>\n";
  }
  h << "</table>\n";
  if (!r.skipped.empty()) {
    h << "<p>Not tested: ";
    for (std::size_t k = 0; k < r.skipped.size(); ++k) {
      h << (k ? "; " : "") << "<b>" << XmlEscape(r.skipped[k].name) << "</b> ("
        << XmlEscape(r.skipped[k].why) << ")";
    }
    h << ".</p>\n";
  }
  h << "<details><summary>What the effects mean</summary><dl>";
  for (const EffectTrial& t : r.effects) {
    h << "<dt><b>" << XmlEscape(t.name) << "</b></dt><dd>" << XmlEscape(t.explanation)
      << "<br><i>Evidence:</i> " << XmlEscape(t.evidence) << "</dd>";
  }
  h << "</dl></details>\n";
}

// The regimes holding more of the error than of the data.
void HtmlWhereTheErrorLies(std::ostream& h, const DiagnosisResult& r) {
  h << "<h2>Where the error lies</h2>\n";
  if (r.where.empty()) {
    h << "<p>No regime holds a share of the error clearly beyond its share of the data.</p>\n";
  } else {
    h << "<table><tr><th class='l'>output</th><th class='l'>region</th><th>share of rows</th>"
      << "<th>share of |error|</th><th>MAE W</th><th>bias W</th><th>z</th></tr>\n";
    for (const GapRegion& g : r.where) {
      h << "<tr><td class='l'>" << (g.output == "q_th" ? "Q<sub>u</sub>" : "P<sub>el</sub>")
        << "</td><td class='l'>" << XmlEscape(RegionText(g)) << "</td><td>"
        << Fixed(100 * g.share_of_rows, 1) << " %</td><td>" << Fixed(100 * g.share_of_abs_error, 1)
        << " %</td><td>" << Fixed(g.mae_w, 2) << "</td><td>" << Fixed(g.bias_w, 2) << "</td><td>"
        << Fixed(g.z, 1) << "</td></tr>\n";
    }
    h << "</table>\n<p>z: how many bootstrap standard deviations (resampling whole hours) the "
      << "region's share of the absolute error exceeds its share of the rows. Bias = predicted − "
      << "measured.</p>\n";
  }
}

// Held-out residuals (predicted − measured) of the base and final models,
// and the base model's absolute residuals.
struct HeldOutResiduals {
  std::vector<double> t, rp_base, rq_base, rp_final, rq_final, abs_q, abs_p;
};

HeldOutResiduals Residuals(const DiagnosisTrace& tr) {
  HeldOutResiduals res;
  res.t.assign(tr.time_s.begin(), tr.time_s.end());
  for (std::size_t i = 0; i < res.t.size(); ++i) {
    res.rp_base.push_back(tr.p_el_base_w[i] - tr.p_el_meas_w[i]);
    res.rq_base.push_back(tr.q_th_base_w[i] - tr.q_th_meas_w[i]);
    res.rp_final.push_back(tr.p_el_final_w[i] - tr.p_el_meas_w[i]);
    res.rq_final.push_back(tr.q_th_final_w[i] - tr.q_th_meas_w[i]);
    res.abs_q.push_back(std::fabs(res.rq_base.back()));
    res.abs_p.push_back(std::fabs(res.rp_base.back()));
  }
  return res;
}

// Held-out residuals of Q_u and P_el over time.
void HtmlResidualsOverTime(std::ostream& h, const DiagnosisResult& r, const HeldOutResiduals& res) {
  const bool has_final = r.final_variant != r.base_variant;
  for (const auto& [name, base_r, final_r] : {std::tuple{"Q_u", &res.rq_base, &res.rq_final},
                                              std::tuple{"P_el", &res.rp_base, &res.rp_final}}) {
    SvgXYOptions o;
    o.title = std::string("Held-out residual of ") + name + " (predicted − measured)";
    o.x_label = "time (UTC)";
    o.y_label = "W";
    o.x_is_unix_time = true;
    std::vector<SvgSeries> ser = {{r.base_variant, "#d62728", res.t, *base_r, false}};
    if (has_final) ser.push_back({r.final_variant, "#1f77b4", res.t, *final_r, false});
    h << SvgXYPlot(ser, o);
  }
}

// Mean absolute residuals over hour × AOI (Q_u) and the sun's position (P_el).
void HtmlResidualMaps(std::ostream& h, const DiagnosisTrace& tr, const HeldOutResiduals& res) {
  SvgHeatmap m = Heat(tr.hour_of_day, tr.aoi_deg, res.abs_q, Edges(0, 24, 1), Edges(0, 90, 10));
  m.title = "Mean |Q_u residual|, hour × AOI";
  m.x_label = "hour of local solar time";
  m.y_label = "angle of incidence (°)";
  m.value_label = "W";
  h << SvgHeatmapPlot(m);
  SvgHeatmap s = Heat(tr.sun_azimuth_deg, tr.sun_elevation_deg, res.abs_p, Edges(30, 330, 15),
                      Edges(0, 70, 5));
  s.title = "Mean |P_el residual|, sun azimuth × elevation";
  s.x_label = "sun azimuth (°, 180 = south)";
  s.y_label = "sun elevation (°)";
  s.value_label = "W";
  h << SvgHeatmapPlot(s) << "<br>\n";
}

// Measured against predicted Q_u and P_el.
void HtmlMeasuredVsPredicted(std::ostream& h, const DiagnosisResult& r) {
  const DiagnosisTrace& tr = r.trace;
  const bool has_final = r.final_variant != r.base_variant;
  for (const auto& [name, meas, base_pred, final_pred] :
       {std::tuple{"Q_u", &tr.q_th_meas_w, &tr.q_th_base_w, &tr.q_th_final_w},
        std::tuple{"P_el", &tr.p_el_meas_w, &tr.p_el_base_w, &tr.p_el_final_w}}) {
    SvgXYOptions o;
    o.title = std::string("Measured vs predicted ") + name + " (held-out)";
    o.x_label = "measured (W)";
    o.y_label = "predicted (W)";
    o.diagonal = true;
    o.width = 460;
    o.height = 360;
    std::vector<SvgSeries> ser = {{r.base_variant, "#d62728", *meas, *base_pred, true}};
    if (has_final) ser.push_back({r.final_variant, "#1f77b4", *meas, *final_pred, true});
    h << SvgXYPlot(ser, o);
  }
}

// Error share by regime: the bins of the drivers holding the flagged
// regions (or of a few standard ones).
void HtmlErrorShareByRegime(std::ostream& h, const DiagnosisResult& r) {
  std::vector<std::string> drivers;
  for (const GapRegion& g : r.where) {
    if (g.driver2.empty() && std::find(drivers.begin(), drivers.end(), g.driver) == drivers.end())
      drivers.push_back(g.driver);
  }
  for (const char* d : {"hour_of_day", "aoi_deg", "g_poa_w_m2"}) {
    if (drivers.size() < 3 && std::find(drivers.begin(), drivers.end(), d) == drivers.end())
      drivers.push_back(d);
  }
  for (const std::string& output : {std::string("q_th"), std::string("p_el")}) {
    std::vector<SvgBarGroup> groups;
    for (const std::string& d : drivers) {
      for (const GapRegion& b : r.where_bins) {
        if (b.output != output || b.driver != d || !b.driver2.empty()) continue;
        groups.push_back({RegionText(b), {b.share_of_rows, b.share_of_abs_error}});
      }
    }
    if (groups.empty()) continue;
    h << SvgBarPlot(std::string("Share of rows and of |error| by regime, ") +
                        (output == "q_th" ? "Q_u" : "P_el"),
                    {"share of rows", "share of |error|"}, {"#9aa9b8", "#d62728"}, groups);
  }
}

// The plots: residuals over time and over the sun's path, measured against
// predicted, and the error's share by regime.
void HtmlPlots(std::ostream& h, const DiagnosisResult& r) {
  const HeldOutResiduals res = Residuals(r.trace);
  h << "<h2>Plots</h2>\n";
  HtmlResidualsOverTime(h, r, res);
  HtmlResidualMaps(h, r.trace, res);
  HtmlMeasuredVsPredicted(h, r);
  HtmlErrorShareByRegime(h, r);
}

// Each day's role, rows and objectives, and the run's cost.
void HtmlDays(std::ostream& h, const DiagnosisResult& r) {
  h << "<h2>Days</h2>\n<table><tr><th class='l'>day</th><th class='l'>role</th><th>rows</th>"
    << "<th>base objective W/m²</th><th>final objective W/m²</th></tr>\n";
  for (const DiagnosisDay& d : r.days) {
    h << "<tr><td class='l'>" << d.date << "</td><td class='l'>"
      << (d.heldout ? "held-out" : "training") << "</td><td>" << d.rows << "</td><td>"
      << (d.heldout ? Fixed(d.base_objective_w_m2, 3) : "") << "</td><td>"
      << (d.heldout ? Fixed(d.final_objective_w_m2, 3) : "") << "</td></tr>\n";
  }
  h << "</table>\n<p>" << r.identifications << " identifications, " << Fixed(r.wall_time_s, 1)
    << " s.</p>\n</body></html>\n";
}

}  // namespace

std::string DiagnosisReportHtml(const DiagnosisResult& r) {
  std::ostringstream h;
  HtmlHead(h, r);
  HtmlVerdict(h, r);
  HtmlErrorSummary(h, r);
  HtmlLadder(h, r);
  HtmlEffectsTested(h, r);
  HtmlWhereTheErrorLies(h, r);
  HtmlPlots(h, r);
  HtmlDays(h, r);
  return h.str();
}

bool WriteDiagnosisReport(const std::string& dir, const DiagnosisResult& result,
                          std::string* error) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    *error = dir + ": cannot create the report directory: " + ec.message();
    return false;
  }
  const std::string base = (std::filesystem::path(dir) / "").string();
  return WriteTextFileAtomically(base + "report.json", DiagnosisReportJson(result), error) &&
         WriteTextFileAtomically(base + "report.html", DiagnosisReportHtml(result), error);
}

}  // namespace pvtwin

// The reports of `pvtwin diagnose` (core/diagnosis.h).
//
// report.json, the contract of doc/contracts.md ("Diagnosis report"), extended with
// more fields, never renamed:
//   { "base_variant": "1N1Cwr",
//     "gap": {"mae_p_el_w", "mae_q_th_w", "nmae_p_el", "nmae_q_th",     held-out, base model
//             "rows", "objective_w_m2",
//             "bias_p_el_w", "bias_q_th_w",          mean predicted − measured, W
//             "bias_share_p_el", "bias_share_q_th"},  |bias| / MAE
//     "where": [{"driver": "aoi_deg", "range": [60, 90],
//                "share_of_abs_error": 0.4, "output": "q_th",             "p_el" | "q_th"
//                "share_of_rows", "bias_w", "mae_w", "rows",
//                "z",                      block-bootstrap z of the excess share
//                "label",                  e.g. the date of a "day" region
//                "and": {"driver": "sun_elevation_deg", "range": [..]}    2-D cells only
//               }],
//     "effects": [{"name": "wind", "significant": true, "shrink_pct": 35.0,
//                  "heldout_mae_before_w", "heldout_mae_after_w",        MAE P_el + MAE Q_u, W
//                  "evidence": "...",
//                  "variant", "tested_against", "accepted_at_step",
//                  "p_value" (one-sided Wilcoxon), "sign_test_p", "t_stat",
//                  "units_better", "units", "evidence_r", "evidence_z",
//                  "evidence_output", "explanation", "advice" (one sentence for
//                  the site, from the effect's module), "fit_ok", "failure",
//                  "irradiance_bias_k", "irradiance_bias_p" (irradiance_bias only)}],   ranked
//     "verdict": "wind",                       an effect, "none" or "unknown"
//     "verdict_sentence": "...",
//     "final_variant", "ladder": [{"variant", "added", "heldout_mae_w",
//                                  "mae_p_el_w", "mae_q_th_w", "objective_w_m2",
//                                  "shrink_pct", "p_value"}],
//     "noise_floor": {"mae_p_el_w", "mae_q_th_w", "objective_w_m2", "ratio"},
//     "test_unit": "day" | "hour", "low_confidence": bool, "notes": [...],
//     "skipped_effects": [{"name", "why"}],
//     "days": [{"date", "start_s", "heldout", "rows", "base_objective_w_m2",
//               "final_objective_w_m2"}],
//     "step_s", "identifications", "wall_time_s" }
// Numbers that are not finite are written as null.
//
// report.html: one self-contained page for a plant engineer (no external
// assets): the verdict in one sentence, the ladder and effects tables, the
// regions of concentrated error, and SVG plots drawn here: residuals against
// time, mean |residual| over hour × AOI and sun azimuth × elevation,
// measured against predicted, and the error share by regime.
#pragma once

#include <string>

#include "core/diagnosis/diagnosis.h"

namespace pvtwin {

std::string DiagnosisReportJson(const DiagnosisResult& result);

std::string DiagnosisReportHtml(const DiagnosisResult& result);

// Writes DIR/report.json and DIR/report.html (creating DIR). False with
// *error naming the path on failure.
bool WriteDiagnosisReport(const std::string& dir, const DiagnosisResult& result,
                          std::string* error);

}  // namespace pvtwin

// The band of a day's performance index and the performance alarm, both
// from the monitor's residual model: the daily energy errors of the model
// that scored the recent days (issue 53, item 3). Pure computation on
// DayPerformance rows (monitoring.h), as performance_daily stores them.
//
// Residual model. A day's index is pi = E_meas / E_model (ScoreDay); on a
// healthy plant e = ln pi is the model's error of the day's energy. A day's
// minutes err together (a bias of the fit that grows with the sun, a sky the
// model's inputs render wrongly for hours), so per-minute residual
// quantiles say little about a day's energy: the units are whole days, as
// the forecast bands' conformal calibration takes them (forecast_bands.h).
// Assumption: on a healthy plant the errors e of the recent scored days are
// exchangeable with today's: the same model structure, the same season
// within reference_days, each day scored alike, by the parameters the
// daemon held the night after it (with [calibration] refit_full_window a fit
// that has seen the day among the window's 14: the error of the model as
// the daemon runs it, which is what the band is to cover). With q10 ≤ q90
// the split-conformal quantiles of the reference days' e (the
// ⌊0.1·(n + 1)⌋-th and ⌈0.9·(n + 1)⌉-th smallest of n),
//   pi_low = pi·exp(−q90),   pi_high = pi·exp(−q10)
// is the split-conformal 10–90 % band of the plant's own index (pi with the
// model's daily error taken out): it holds 1 exactly when q10 ≤ e ≤ q90,
// on at least 80 % of healthy days (at most 10 % of them above the band,
// at most 10 % below; 86 % in all with 28 reference days). A biased model
// (a structure the plant does not share) moves q10 and q90 together, and
// the band with them. Reference days: of the days of the reference_days
// before the day that are scored for the output, except those an alarm
// judged a fault (the days of an excursion of the CUSUM that ended in an
// alarm), the `neighbours`
// whose expected energy of the output is nearest the day's (in ratio): the
// model's daily error depends on the sky and the operation (2N1Ccolwr on a
// plant with an IAM errs 1–2 % lower on clear days than on overcast ones),
// so a clear day is judged against clear days, as the forecast bands take
// their quantiles by irradiance class. With fewer than min_reference_days
// of them the day has no band (NaN), and takes no part in the alarm.
//
// Regime test (issue 53: a history that starts in another weather). The
// band assumes the day's (regime, error) exchangeable with its reference
// days'; the regime x = ln E_model is known before the error. With the
// same conformal ranks, x_10 ≤ x_90 of the reference days' x: a day
// outside [x_10, x_90] is ordinary (probability up to 2/(n + 1), 13 % for
// 14 days: the clearest day of a month, on which a clipping inverter
// shows, is one), but a day beyond it by more than its width w = x_90 −
// x_10 is farther from every reference day than they lie from one another:
// the references hold no evidence of the model's error in its regime (the
// first clear day after 10 overcast ones, whose energy is 3 times theirs,
// and the model's error on it 2 % lower). Such a day's judgement is
// withheld: no band (NaN), no part in the CUSUM (IndexDay::withheld); it
// stays a reference day for the days after, so the next day of its regime
// is judged. No tuned number: the ranks are the band's, the distance the
// reference selection's, the scale the references' own.
//
// Alarm: Page's one-sided CUSUM (E. S. Page, "Continuous inspection
// schemes", Biometrika 41, 1954) of the standardised daily errors, with the
// reference's location c = (q10 + q90)/2 and scale σ = (q90 − q10)/(2·z90),
// z90 = 1.2816 the normal 90 % quantile:
//   z_d = (e_d − c)/σ,   S_d = max(0, S_{d−1} − z_d − k)
// over the days with a band, in time order. An alarm on the day S reaches h
// when the excursion (the days since S was last 0) holds at least min_days
// days; S then starts again from 0. Several moderately low days together
// alarm; one day at its band's edge (z = −1.28) adds 0.28 σ and does not.
// Band and CUSUM are one pass over the days' pi (FollowIndex).
//
// Which days leave the reference (issue 53: the mixed reference). Only an
// alarm's excursion, from the alarm on: the alarm is the judgement that its
// days are a fault, and a fault's days must not widen the band that is to
// find it again. The days of an excursion still open are evidence under
// judgement, not yet a fault, and stay in the reference: a healthy regime
// the reference has not yet seen (the first clear days of a month, on which
// the model errs 1–2 % lower) reads low against the other regimes, opens an
// excursion, and, were its days left out while it is open, every later day
// of that regime would again be judged against the other regimes alone, the
// excursion kept open by its own exclusion until it alarms. Kept in, the
// regime's first days are the next one's nearest references. Assumption: a
// fault worth an alarm shifts the index by several band widths (clipping at
// the inverter's limit: 8–10 % on a clear day against a band of ±0.3 %), so
// its first days, once among the references, widen the band (rank 1 of 14
// is the lowest reference) but the CUSUM, fed by the days before, still
// reaches h within min_days of them. A conformalized regression over all
// reference days (a line e on ln E_model, CV+) was measured and not taken:
// the model's error is concave in ln E_model (clear days fall below the
// line), so the clear days' neighbours judge them better than the line
// (doc/validation.md).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/monitor/monitoring.h"

namespace pvtwin {

struct IndexBandOptions {
  // The days before the scored one whose errors form its reference: a
  // month, one season, enough days for the 10 % quantiles.
  int reference_days = 28;
  // Fewest reference days for a band; 9 is the least n whose extremes
  // already hold a new day with probability (n − 1)/(n + 1) ≥ 0.8 (no band
  // below it, whatever this says).
  int min_reference_days = 9;
  // Of those, the days most like the scored one in expected energy: half
  // of a month, still twice the days of a band's least reference.
  int neighbours = 14;
};

struct IndexCusumOptions {
  // Reference value k, in σ of the daily error: half the shift the alarm is
  // built to find, a daily loss of 2σ (the band's edge lies at 1.28σ).
  double k_sigma = 1.0;
  // Decision interval h, in σ, from the in-control run length: with k = 1
  // Siegmund's approximation ARL0 ≈ (e^{2b} − 2b − 1)/2, b = h + 1.166,
  // gives about 2000 scored days between false alarms of one output for
  // h = 3, and an expected 3.7 days to find a loss of 2σ (2.0 for 3σ).
  double h_sigma = 3.0;
  // Fewest days in the excursion ([monitor] alarm_days): the evidence of so
  // many days together, never one day's.
  int min_days = 3;
};

// One day of an output in FollowIndex: every day scored for the output.
struct IndexDay {
  std::int64_t day_start_s = 0;
  double pi = 0.0;
  double e_model_wh = 0.0;       // the output's expected energy: the day's regime
  double low = 0.0, high = 0.0;  // the band; NaN without enough reference days
  bool banded = false;           // has a band, and so a part in the CUSUM
  // Judgement withheld: enough reference days, but the day's expected
  // energy lies beyond their conformal range by more than its width (a
  // regime they do not hold); no band (NaN), no part in the CUSUM, still a
  // reference for later days.
  bool withheld = false;
  double z = 0.0;      // standardised error of the day (σ); 0 without a band
  double s = 0.0;      // S after the day (σ); after an alarm the next starts from 0
  int run_days = 0;    // days of the excursion up to this day (0: S is 0)
  bool alarm = false;  // S reached h with run_days >= min_days on this day
  // Left out of later days' reference: part of an excursion that ended in
  // an alarm (the days of an open excursion stay in it).
  bool suspect = false;
};

// Band and CUSUM of one output over `days` (time order, as stored; only
// their pi is read).
std::vector<IndexDay> FollowIndex(std::span<const DayPerformance> days, bool thermal,
                                  const IndexBandOptions& bands, const IndexCusumOptions& cusum);

// The first day of the plant's newest change as the alarm sees it (-1: no
// alarm among `days`, FollowIndex's output): the maximum-likelihood change
// point of a step loss of unknown size in the standardised daily errors z
// (D. V. Hinkley, "Inference about the change-point in a sequence of random
// variables", Biometrika 57, 1970), over the banded days up to the newest
// alarm: the day τ that maximises (Σ_{t ≥ τ} −z_t)² / (the banded days from
// τ on), with a positive sum. Before the change z is the healthy plant's,
// standardised to N(0, 1) by its reference days; after it its mean is
// lowered by the loss, which the estimate does not need to know. Unlike the
// day after the CUSUM was last 0, it is not moved early by mildly low days
// before the change (counted in, days lower by less than about half the
// loss lower the likelihood), and a loss seen on clear days only, on which
// the CUSUM returns to 0 on the cloudy days between and alarms again from
// 0, stays one change as long as the days between carry less evidence of
// its end than the days after of its going on. The diagnosis judges the
// days from it (daemon/service/nightly_diagnosis.h): a model fitted across
// a change judges neither state. Withheld days take no part.
std::int64_t ChangeOnsetS(std::span<const IndexDay> days);

// Sets day->pi_*_low and pi_*_high of each output day is scored for, as
// FollowIndex over `earlier` (days before it, time order) and the day.
void SetIndexBands(std::span<const DayPerformance> earlier, const IndexBandOptions& bands,
                   const IndexCusumOptions& cusum, DayPerformance* day);

}  // namespace pvtwin

// core/monitor/index_band.h on analytic cases: the band of a day is the
// split-conformal 10–90 % band of the reference days' errors (type-7
// quantiles by hand), holds 1 on 80 % of exchangeable days, and the CUSUM
// alarms on several moderately low days together, never on one day's band
// edge; days of an alarm stay out of later references, the days of an open
// excursion stay in.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/monitor/index_band.h"
#include "tests/support/fixtures.h"

namespace pvtwin {
namespace {

using testing::kDayS;
using testing::kJune1_2024UtcS;
constexpr double kZ90 = 1.2815515655446004;

// A day scored for electricity only, with pi = exp(error).
DayPerformance DayWithError(int d, double error) {
  DayPerformance p;
  p.day_start_s = kJune1_2024UtcS + d * kDayS;
  p.scored_el = true;
  p.pi_el = std::exp(error);
  p.e_el_model_wh = 1000.0;  // every day alike: the nearest are the most recent
  p.pi_el_low = p.pi_el_high = std::nan("");
  p.pi_th = p.pi_th_low = p.pi_th_high = std::nan("");
  return p;
}

// Days 0 … n−1 with the given errors, each banded from the days before.
std::vector<DayPerformance> Banded(const std::vector<double>& errors,
                                   const IndexBandOptions& bands = {},
                                   const IndexCusumOptions& cusum = {}) {
  std::vector<DayPerformance> days;
  for (std::size_t d = 0; d < errors.size(); ++d) {
    DayPerformance p = DayWithError(static_cast<int>(d), errors[d]);
    SetIndexBands(days, bands, cusum, &p);
    days.push_back(p);
  }
  return days;
}

// The ranks of the split-conformal quantiles among n reference errors.
struct Ranks {
  std::size_t low, high;
};
Ranks ConformalRanks(std::size_t n) {
  return {
      static_cast<std::size_t>(std::floor(0.1 * static_cast<double>(n + 1) + 1e-9)),
      std::min(n, static_cast<std::size_t>(std::ceil(0.9 * static_cast<double>(n + 1) - 1e-9)))};
}

TEST(IndexBand, TheSplitConformalQuantilesOfTheReferenceDaysErrors) {
  // 20 reference days with errors −0.05, −0.045, …, 0.045 in a shuffled
  // order (7·d mod 20).
  std::vector<double> errors;
  for (int d = 0; d < 20; ++d) errors.push_back(0.005 * ((7 * d) % 20 - 10));
  std::vector<DayPerformance> earlier;
  for (int d = 0; d < 20; ++d) earlier.push_back(DayWithError(d, errors[d]));
  IndexBandOptions all;
  all.neighbours = all.reference_days;
  DayPerformance today = DayWithError(20, 0.02);
  SetIndexBands(earlier, all, IndexCusumOptions{}, &today);
  // n = 20: the ⌊2.1⌋ = 2nd and the ⌈18.9⌉ = 19th smallest.
  const double q10 = -0.045, q90 = 0.04;
  EXPECT_NEAR(today.pi_el_low, std::exp(0.02 - q90), 1e-12);
  EXPECT_NEAR(today.pi_el_high, std::exp(0.02 - q10), 1e-12);
  EXPECT_TRUE(std::isnan(today.pi_th_low));  // not scored for heat: no band
  // One reference day fewer than min_reference_days: no band.
  IndexBandOptions strict = all;
  strict.min_reference_days = 21;
  DayPerformance early = DayWithError(20, 0.02);
  SetIndexBands(earlier, strict, IndexCusumOptions{}, &early);
  EXPECT_TRUE(std::isnan(early.pi_el_low) && std::isnan(early.pi_el_high));
  // Days older than reference_days are not part of it: days 10 … 19, whose
  // ranks 1 and 10 are their extremes.
  IndexBandOptions recent = all;
  recent.reference_days = 10;
  DayPerformance later = DayWithError(20, 0.02);
  SetIndexBands(earlier, recent, IndexCusumOptions{}, &later);
  const auto [lo, hi] = std::minmax_element(errors.begin() + 10, errors.end());
  EXPECT_NEAR(later.pi_el_low, std::exp(0.02 - *hi), 1e-12);
  EXPECT_NEAR(later.pi_el_high, std::exp(0.02 - *lo), 1e-12);
  EXPECT_GT(*lo, -0.045);  // the older days' quantile is not among them
}

TEST(IndexBand, HoldsOneOnAtLeastEightyPercentOfDaysWhoseErrorsAreExchangeable) {
  // A biased model (errors around −4 %, σ 3 %): the band follows the bias.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> error(-0.04, 0.03);
  std::vector<double> errors(400);
  for (double& e : errors) e = error(rng);
  IndexCusumOptions never;
  never.k_sigma = 1e9;  // S stays 0: no alarm, no suspect days, the band alone
  const IndexBandOptions bands;
  const std::vector<DayPerformance> days = Banded(errors, bands, never);
  int banded = 0, hold = 0;
  double expected = 0.0;  // Σ (high rank − low rank)/(n + 1) over the banded days
  for (std::size_t d = 0; d < days.size(); ++d) {
    if (std::isnan(days[d].pi_el_low)) continue;
    ++banded;
    hold += days[d].pi_el_low <= 1.0 && 1.0 <= days[d].pi_el_high;
    const std::size_t n = std::min<std::size_t>(d, static_cast<std::size_t>(bands.neighbours));
    const Ranks r = ConformalRanks(n);
    expected += static_cast<double>(r.high - r.low) / static_cast<double>(n + 1);
  }
  EXPECT_EQ(banded, 400 - 9);
  expected /= banded;
  EXPECT_GE(expected, 0.8);
  EXPECT_LE(expected, 0.9);
  // Binomial spread over 391 days: ± 1.8 %.
  EXPECT_NEAR(static_cast<double>(hold) / banded, expected, 0.05);
}

TEST(IndexBand, ADayIsJudgedAgainstTheDaysMostLikeItInExpectedEnergy) {
  // 14 clear days (2000 Wh expected ± 5 %, the model 2 % high) and 14
  // overcast ones (500 Wh ± 5 %, the model 1 % low), alternating, each
  // with ±0.2 % noise.
  std::vector<DayPerformance> earlier;
  for (int d = 0; d < 28; ++d) {
    const bool clear = d % 2 == 0;
    DayPerformance p = DayWithError(d, (clear ? -0.02 : 0.01) + 0.002 * ((d / 2) % 3 - 1));
    p.e_el_model_wh = (clear ? 2000.0 : 500.0) * (1.0 + 0.05 * ((d / 2) % 3 - 1));
    earlier.push_back(p);
  }
  // A clear day 2 % low is within its band (the clear days' error); an
  // overcast one 2 % low is below it.
  DayPerformance clear = DayWithError(28, -0.02), overcast = DayWithError(28, -0.02);
  clear.e_el_model_wh = 1900.0;
  overcast.e_el_model_wh = 550.0;
  SetIndexBands(earlier, IndexBandOptions{}, IndexCusumOptions{}, &clear);
  SetIndexBands(earlier, IndexBandOptions{}, IndexCusumOptions{}, &overcast);
  EXPECT_NEAR(clear.pi_el_low, std::exp(-0.02 - (-0.02 + 0.002)), 1e-12);
  EXPECT_NEAR(clear.pi_el_high, std::exp(-0.02 - (-0.02 - 0.002)), 1e-12);
  EXPECT_LT(overcast.pi_el_high, 1.0);
  EXPECT_NEAR(overcast.pi_el_high, std::exp(-0.02 - (0.01 - 0.002)), 1e-12);
}

TEST(IndexCusum, ThreeDaysTwoSigmaLowAlarmOneBandEdgeDoesNot) {
  // Reference: 30 days alternating ∓σ·z90, so that every band's 10 and 90 %
  // quantiles are −a and a, and its σ is known. 30, not 20: an open
  // excursion's days stay in the reference, so the third low day's holds
  // the first two; with n = 30 the low rank is ⌊3.1⌋ = 3 and two low days
  // do not reach it (with 20 days, rank 2, they would widen the band).
  const double sigma = 0.03, a = sigma * kZ90;
  std::vector<double> errors;
  for (int d = 0; d < 30; ++d) errors.push_back(d % 2 == 0 ? -a : a);
  // One day at its band's lower edge (z = −z90), then two normal days, then
  // three days 2.1σ low.
  errors.push_back(-a);
  errors.push_back(0.0);
  errors.push_back(0.0);
  for (int d = 0; d < 3; ++d) errors.push_back(-2.1 * sigma);
  IndexBandOptions bands;
  bands.reference_days = 30;  // exactly the alternating days at day 30
  bands.neighbours = 30;
  const std::vector<DayPerformance> days = Banded(errors, bands);
  const std::vector<IndexDay> run = FollowIndex(days, false, bands, IndexCusumOptions{});
  ASSERT_EQ(run.size(), errors.size());
  EXPECT_FALSE(run[8].banded);  // eight reference days: no band, no part in the CUSUM
  EXPECT_TRUE(run[9].banded);
  // Day 30: the band edge, z = −z90, S = z90 − 1 = 0.28: no alarm.
  const IndexDay& edge = run[30];
  EXPECT_EQ(edge.day_start_s, kJune1_2024UtcS + 30 * kDayS);
  EXPECT_NEAR(edge.z, -kZ90, 1e-9);
  EXPECT_NEAR(edge.s, kZ90 - 1.0, 1e-9);
  EXPECT_FALSE(edge.alarm);
  EXPECT_NEAR(days[30].pi_el_high, 1.0, 1e-12);  // the top of its band touches 1
  // Days 33–35, 2.1σ low each: S = 1.1, 2.2, 3.3 σ; the alarm on the third.
  for (int d = 33; d <= 35; ++d) {
    const IndexDay& c = run[static_cast<std::size_t>(d)];
    ASSERT_EQ(c.day_start_s, kJune1_2024UtcS + d * kDayS);
    EXPECT_NEAR(c.z, -2.1, 1e-9) << d;
    EXPECT_EQ(c.alarm, d == 35) << d;
    EXPECT_EQ(c.run_days, d - 32) << d;
  }
  int alarms = 0;
  for (const IndexDay& c : run) alarms += c.alarm;
  EXPECT_EQ(alarms, 1);
}

TEST(IndexCusum, OneVeryLowDayWaitsForTheMinimumRunAndTheAlarmDaysLeaveTheReference) {
  std::vector<double> errors(14, 0.0);
  for (int d = 0; d < 14; ++d) errors[static_cast<std::size_t>(d)] = 0.02 * ((d % 5) - 2) / 2.0;
  errors.push_back(-0.5);  // snow on the field: far below any band
  errors.push_back(0.0);
  errors.push_back(0.0);
  const std::vector<DayPerformance> days = Banded(errors);
  IndexCusumOptions options;
  options.min_days = 3;
  std::vector<IndexDay> run = FollowIndex(days, false, IndexBandOptions{}, options);
  ASSERT_EQ(run.size(), 17u);
  // Day 14 alone does not alarm; the alarm waits for the third day of its
  // excursion, which the low day keeps open.
  EXPECT_FALSE(run[14].alarm);
  EXPECT_FALSE(run[15].alarm);
  EXPECT_TRUE(run[16].alarm);
  EXPECT_EQ(run[16].run_days, 3);
  for (std::size_t k = 0; k < run.size(); ++k) EXPECT_EQ(run[k].suspect, k >= 14) << k;
  // The alarm's days do not widen the next day's reference: its band is
  // the one of the 14 calm days alone.
  std::vector<DayPerformance> calm(days.begin(), days.begin() + 14);
  DayPerformance next = DayWithError(17, 0.0), next_calm = DayWithError(17, 0.0);
  SetIndexBands(days, IndexBandOptions{}, options, &next);
  SetIndexBands(calm, IndexBandOptions{}, options, &next_calm);
  EXPECT_NEAR(next.pi_el_low, next_calm.pi_el_low, 1e-12);
  EXPECT_NEAR(next.pi_el_high, next_calm.pi_el_high, 1e-12);
  // With min_days = 1 the same day alarms at once.
  options.min_days = 1;
  run = FollowIndex(days, false, IndexBandOptions{}, options);
  EXPECT_TRUE(run[14].alarm);
  EXPECT_FALSE(run[15].alarm);  // S starts again from 0 after it
}

TEST(IndexBand, ADayOutsideItsReferencesRegimeIsNotJudgedAndAHealthyPlantDoesNotAlarm) {
  // A history that starts in another regime: 12 overcast days (500–580 Wh
  // expected, the model right within ±0.2 %), then clear days (2000–2040
  // Wh, the model 2 % high: healthy, a regime effect of its structure). The
  // first clear days' nearest days are overcast; judged against them, 2 %
  // is 13 σ low, and the CUSUM alarms on the third clear day.
  std::vector<double> errors;
  std::vector<double> e_model_wh;
  for (int d = 0; d < 40; ++d) {
    const bool clear = d >= 12;
    const double noise = 0.002 * (d % 3 - 1);
    errors.push_back((clear ? -0.02 : 0.0) + noise);
    e_model_wh.push_back(clear ? 2000.0 + 10.0 * ((7 * d) % 5) : 500.0 + 20.0 * (d % 5));
  }
  // From day 32 on, a fault: 5 % less on the clear days.
  for (int d = 32; d < 40; ++d) errors[static_cast<std::size_t>(d)] -= 0.05;
  const IndexBandOptions bands;
  const IndexCusumOptions cusum;
  std::vector<DayPerformance> days;
  for (int d = 0; d < 40; ++d) {
    DayPerformance p = DayWithError(d, errors[static_cast<std::size_t>(d)]);
    p.e_el_model_wh = e_model_wh[static_cast<std::size_t>(d)];
    SetIndexBands(days, bands, cusum, &p);
    days.push_back(p);
  }
  const std::vector<IndexDay> run = FollowIndex(days, false, bands, cusum);
  ASSERT_EQ(run.size(), 40u);
  // Day 12, the first clear day: 12 reference days, all overcast, its
  // expected energy beyond every one of theirs: judgement withheld.
  EXPECT_TRUE(run[12].withheld);
  EXPECT_FALSE(run[12].banded);
  EXPECT_TRUE(std::isnan(days[12].pi_el_low) && std::isnan(days[12].pi_el_high));
  // Day 13 lies within its references' range (day 12 among them): judged.
  EXPECT_TRUE(run[13].banded);
  EXPECT_FALSE(run[13].withheld);
  // The healthy days raise no alarm; the fault does, on its third day.
  int first_alarm = -1;
  for (int d = 0; d < 40 && first_alarm < 0; ++d) {
    if (run[static_cast<std::size_t>(d)].alarm) first_alarm = d;
  }
  EXPECT_GE(first_alarm, 32);
  EXPECT_LE(first_alarm, 34);
}

TEST(IndexCusum, AnOpenExcursionsDaysStayInTheReferenceSoANewHealthyRegimeIsLearned) {
  // A mixed reference (issue 53): 20 days alternating overcast (500–540 Wh
  // expected, the model right) and broken (1500–1580 Wh, the model 0.5 %
  // high), then clear days (2000–2080 Wh, within the regime test's range,
  // the model 1.2 % high: healthy, a regime error of its structure), each
  // with ±0.2 % noise; from day 32 a fault, 5 % less. The first clear days
  // read low against the broken ones and open an excursion. Were its days
  // left out while it is open, every clear day would be judged against the
  // broken days alone (z about −2 to −3 each) and alarm on the third (day
  // 22), again and again; kept in, the next clear day has them among its
  // nearest days, S stays below h, and the only alarms are the fault's.
  std::vector<DayPerformance> days;
  const IndexBandOptions bands;
  const IndexCusumOptions cusum;
  for (int d = 0; d < 40; ++d) {
    const double noise = 0.002 * (d % 3 - 1);
    double error = d >= 20 ? -0.012 : (d % 2 == 0 ? 0.0 : -0.005);
    if (d >= 32) error -= 0.05;
    DayPerformance p = DayWithError(d, error + noise);
    p.e_el_model_wh = d >= 20 ? 2000.0 + 20.0 * (d % 5)
                              : (d % 2 == 0 ? 500.0 + 10.0 * (d % 5) : 1500.0 + 20.0 * (d % 5));
    SetIndexBands(days, bands, cusum, &p);
    days.push_back(p);
  }
  const std::vector<IndexDay> run = FollowIndex(days, false, bands, cusum);
  ASSERT_EQ(run.size(), 40u);
  EXPECT_FALSE(run[20].withheld);  // the clear days lie within the references' regime range
  EXPECT_LT(run[20].z, -1.0);      // the first clear day reads low: an excursion opens
  EXPECT_GT(run[21].run_days, 0);
  int first_alarm = -1;
  for (int d = 0; d < 40 && first_alarm < 0; ++d) {
    if (run[static_cast<std::size_t>(d)].alarm) first_alarm = d;
  }
  EXPECT_GE(first_alarm, 32);
  EXPECT_LE(first_alarm, 34);
  // The alarm's days leave the reference; the open excursion's before it
  // had not.
  EXPECT_TRUE(run[static_cast<std::size_t>(first_alarm)].suspect);
}

TEST(IndexCusum, TheChangeBeganOnTheFirstDayOfTheAlarmsUnbrokenRun) {
  // 20 calm days, then a loss that stays (8 % from day 20 on): the CUSUM
  // alarms, starts again from 0, and alarms again every few days. The
  // change began on day 20, the first day of the first of those runs.
  std::vector<double> errors(20, 0.0);
  for (int d = 0; d < 20; ++d) errors[static_cast<std::size_t>(d)] = 0.02 * ((d % 5) - 2) / 2.0;
  for (int d = 20; d < 30; ++d) errors.push_back(-0.08);
  const std::vector<DayPerformance> days = Banded(errors);
  const std::vector<IndexDay> run =
      FollowIndex(days, false, IndexBandOptions{}, IndexCusumOptions{});
  ASSERT_EQ(run.size(), 30u);
  int alarms = 0;
  for (const IndexDay& c : run) alarms += c.alarm;
  EXPECT_GE(alarms, 2);  // more than one alarm, so the run of runs is what is tested
  EXPECT_EQ(ChangeOnsetS(run), kJune1_2024UtcS + 20 * kDayS);
  // Only the days up to the first alarm: the same first day.
  std::vector<IndexDay> first;
  for (const IndexDay& c : run) {
    first.push_back(c);
    if (c.alarm) break;
  }
  EXPECT_EQ(ChangeOnsetS(first), kJune1_2024UtcS + 20 * kDayS);
  // The calm days alone: no alarm, no change.
  EXPECT_EQ(ChangeOnsetS(std::vector<IndexDay>(run.begin(), run.begin() + 20)), -1);
}

TEST(IndexCusum, AChangeAfterTheLastOneEndedBeginsAnew) {
  // A loss on days 20–22 that alarms on its third day and ends (a snow
  // cover gone), 11 calm days, and a second loss from day 34: the newest
  // change began on day 34, not on day 20. (A loss that outlasted its alarm
  // would keep the CUSUM above 0 through the calm days: one excursion.)
  std::vector<double> errors(20, 0.0);
  for (int d = 0; d < 20; ++d) errors[static_cast<std::size_t>(d)] = 0.02 * ((d % 5) - 2) / 2.0;
  for (int d = 20; d < 23; ++d) errors.push_back(-0.08);
  for (int d = 23; d < 34; ++d) errors.push_back(0.02 * ((d % 5) - 2) / 2.0);
  for (int d = 34; d < 40; ++d) errors.push_back(-0.08);
  const std::vector<DayPerformance> days = Banded(errors);
  const std::vector<IndexDay> run =
      FollowIndex(days, false, IndexBandOptions{}, IndexCusumOptions{});
  ASSERT_EQ(run.size(), 40u);
  EXPECT_TRUE(run[22].alarm);
  EXPECT_EQ(run[23].run_days, 0);
  EXPECT_EQ(ChangeOnsetS(std::vector<IndexDay>(run.begin(), run.begin() + 34)),
            kJune1_2024UtcS + 20 * kDayS);
  EXPECT_EQ(ChangeOnsetS(run), kJune1_2024UtcS + 34 * kDayS);
}

TEST(IndexCusum, ALossSeenOnClearDaysOnlyIsOneChangeThroughTheCloudyDaysBetween) {
  // An inverter that clips shows on clear days only: a loss on days 20–22
  // (an alarm), three cloudy days without it, on which the CUSUM returns to
  // 0, and the loss again from day 26 (a second alarm). One change, from
  // day 20: the cloudy days between carry no evidence of its end. (The
  // first day of the second alarm's own excursion would date it day 25.)
  std::vector<double> errors;
  for (int d = 0; d < 30; ++d) {
    const bool lossy = (d >= 20 && d < 23) || d >= 26;
    errors.push_back(lossy ? -0.08 : 0.02 * ((d % 5) - 2) / 2.0);
  }
  const std::vector<DayPerformance> days = Banded(errors);
  const std::vector<IndexDay> run =
      FollowIndex(days, false, IndexBandOptions{}, IndexCusumOptions{});
  ASSERT_EQ(run.size(), 30u);
  EXPECT_TRUE(run[22].alarm);
  EXPECT_EQ(run[23].run_days, 0);  // the run is broken: S was 0 on the cloudy day after
  int second_alarm = -1;
  for (int d = 23; d < 30 && second_alarm < 0; ++d) {
    if (run[static_cast<std::size_t>(d)].alarm) second_alarm = d;
  }
  ASSERT_GT(second_alarm, 25);
  EXPECT_EQ(ChangeOnsetS(std::vector<IndexDay>(run.begin(), run.begin() + second_alarm + 1)),
            kJune1_2024UtcS + 20 * kDayS);
}

TEST(IndexCusum, TheChangeIsDatedByTheLikelihoodOfAStepNotByTheLastZero) {
  // Two mildly low days before the loss (z ≈ −1.3, at the band's edge)
  // keep the CUSUM above 0, so its last zero lies on day 17; the step's
  // likelihood puts the change where the loss begins, day 20.
  std::vector<double> errors;
  for (int d = 0; d < 26; ++d) {
    errors.push_back(d >= 20 ? -0.08 : (d == 18 || d == 19) ? -0.02 : 0.02 * ((d % 5) - 2) / 2.0);
  }
  const std::vector<DayPerformance> days = Banded(errors);
  const std::vector<IndexDay> run =
      FollowIndex(days, false, IndexBandOptions{}, IndexCusumOptions{});
  ASSERT_EQ(run.size(), 26u);
  int alarm = -1;
  for (int d = 20; d < 26 && alarm < 0; ++d) {
    if (run[static_cast<std::size_t>(d)].alarm) alarm = d;
  }
  ASSERT_GE(alarm, 20);
  EXPECT_GT(run[19].run_days, 0);  // the excursion opened before the loss
  EXPECT_EQ(ChangeOnsetS(std::vector<IndexDay>(run.begin(), run.begin() + alarm + 1)),
            kJune1_2024UtcS + 20 * kDayS);
}

}  // namespace
}  // namespace pvtwin

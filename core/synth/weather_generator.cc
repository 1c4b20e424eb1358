#include "core/synth/weather_generator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "core/common/units.h"
#include "core/physics/irradiance.h"
#include "core/physics/sky_radiation.h"
#include "core/physics/solar_position.h"
#include "core/synth/pump_controller.h"

namespace pvtwin {
namespace {

constexpr double kSecondsPerDay = 86400.0;
constexpr double kTwoPi = 2.0 * kPi;

double DayOfYear(double time_s) { return DayOfYearUtc(time_s); }

// SplitMix64 step: decorrelated seeds for the separate random streams.
std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Uniform and standard-normal deviates from mt19937_64, independent of the
// standard library's distribution implementations.
class RandomStream {
 public:
  RandomStream(std::uint64_t seed, std::uint64_t stream_id)
      : engine_(SplitMix64(seed ^ SplitMix64(stream_id))) {}

  // Uniform on the open interval (0, 1), 53 random bits.
  double Uniform() { return (static_cast<double>(engine_() >> 11) + 0.5) * 0x1.0p-53; }

  // Standard normal by the Box–Muller transform (pairs, second one cached).
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double radius = std::sqrt(-2.0 * std::log(Uniform()));
    const double angle = kTwoPi * Uniform();
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

// Stream ids: one independent random stream per process.
enum StreamId : std::uint64_t {
  kStreamDayTypes = 1,
  kStreamDayParameters,
  kStreamClouds,
  kStreamTemperature,
  kStreamWind,
  kStreamPump,
  kStreamTank,
};

// Zero-mean, unit-variance AR(1) (a sampled Ornstein–Uhlenbeck process) with
// correlation time tau_s: x ← φ x + √(1 − φ²) ε, φ = exp(−dt/τ). Starts
// from its stationary distribution.
class UnitAr1 {
 public:
  UnitAr1(double tau_s, double dt_s, RandomStream* rng)
      : phi_(std::exp(-dt_s / tau_s)), scale_(std::sqrt(1.0 - phi_ * phi_)), rng_(rng) {
    x_ = rng_->Normal();
  }
  double Next() {
    x_ = phi_ * x_ + scale_ * rng_->Normal();
    return x_;
  }
  double value() const { return x_; }

 private:
  double phi_;
  double scale_;
  RandomStream* rng_;
  double x_ = 0.0;
};

// First-order low pass toward a target: y ← y + (target − y)(1 − exp(−dt/τ)).
class LowPass {
 public:
  LowPass(double tau_s, double dt_s, double initial)
      : alpha_(1.0 - std::exp(-dt_s / tau_s)), y_(initial) {}
  double Update(double target) {
    y_ += alpha_ * (target - y_);
    return y_;
  }

 private:
  double alpha_;
  double y_;
};

// Parameters of one local solar day, drawn when the day starts.
struct DayParameters {
  DayType type = DayType::kClear;
  double clear_factor = 1.0;        // mean k_c of a clear day
  double cloud_fraction = 0.5;      // broken: share of time the sun is hidden
  double cycle_s = 600.0;           // broken: mean sun + cloud period
  double overcast_k = 0.25;         // overcast: mean k_c
  double t_amb_half_range_k = 6.0;  // diurnal half range
  double wind_median_m_s = 2.0;
  double relative_humidity = 0.6;
  double sky_cloud_cover = 0.05;  // c in the long-wave cloud correction
};

DayParameters DrawDayParameters(DayType type, RandomStream* rng) {
  DayParameters p;
  p.type = type;
  // Draw every field on every day so that the stream stays aligned whatever
  // the day type sequence.
  const double u_clear = rng->Uniform();
  const double u_fraction = rng->Uniform();
  const double u_cycle = rng->Uniform();
  const double u_overcast = rng->Uniform();
  p.clear_factor = 0.96 + 0.05 * u_clear;      // 0.96 … 1.01
  p.cloud_fraction = 0.3 + 0.4 * u_fraction;   // 0.3 … 0.7
  p.cycle_s = 300.0 * std::pow(4.0, u_cycle);  // 5 … 20 min
  p.overcast_k = 0.18 + 0.17 * u_overcast;     // 0.18 … 0.35
  switch (type) {
    case DayType::kClear:
      p.t_amb_half_range_k = 6.0;
      p.wind_median_m_s = 2.0;
      p.relative_humidity = 0.6;
      p.sky_cloud_cover = 0.05;
      break;
    case DayType::kBrokenClouds:
      p.t_amb_half_range_k = 4.0;
      p.wind_median_m_s = 3.5;
      p.relative_humidity = 0.7;
      p.sky_cloud_cover = p.cloud_fraction;
      break;
    case DayType::kOvercast:
      p.t_amb_half_range_k = 1.5;
      p.wind_median_m_s = 4.5;
      p.relative_humidity = 0.9;
      p.sky_cloud_cover = 0.95;
      break;
  }
  return p;
}

double LocalSolarDayNumber(double time_s, double longitude_rad) {
  return std::floor((time_s + longitude_rad / kTwoPi * kSecondsPerDay) / kSecondsPerDay);
}

// Local solar time in hours [0, 24) from the hour angle (0 at solar noon,
// 15° per hour, positive in the afternoon).
double SolarHour(double hour_angle_rad) {
  double hour = 12.0 + RadToDeg(hour_angle_rad) / 15.0;
  hour = std::fmod(hour, 24.0);
  return hour < 0.0 ? hour + 24.0 : hour;
}

// The weather of one row, as the plant's operation sees it.
struct RowWeather {
  double g_poa_w_m2 = 0.0;
  double t_amb_c = 0.0;
  double wind_m_s = 0.0;
  double lw_down_w_m2 = 0.0;
  double solar_hour = 12.0;  // local solar time, [0, 24)
};

struct RowOperation {
  double mdot_kg_s = 0.0;
  double t_in_c = 0.0;
};

// The solar loop of WeatherOptions::pump_control: pump, tank or brine, and
// the absorber sensor, advanced one row at a time (one continuous run).
class PlantOperation {
 public:
  PlantOperation(const Plant& plant, const WeatherOptions& options, double dt_s)
      : plant_(plant),
        options_(options),
        dt_s_(dt_s),
        nominal_flow_kg_s_(options.flow_kg_s_per_m2 * plant.area_m2),
        tank_relax_(1.0 - std::exp(-dt_s / options.tank_load_time_constant_s)),
        t_tank_c_(options.t_in_base_c),
        brine_smooth_(3600.0, dt_s, 0.0) {
    control_.dt_on_k = options.pump_dt_on_k;
    control_.dt_off_k = options.pump_dt_off_k;
    control_.min_dwell_s = options.pump_min_dwell_s;
    state_.since_switch_s = options.pump_min_dwell_s;
  }

  // flow_x, mixing_x: this row's flow and mixing noise (unit normal).
  RowOperation Next(const RowWeather& w, double flow_x, double mixing_x) {
    if (options_.pump_control == PumpControl::kIrradiance)
      return NextIrradiance(w, flow_x, mixing_x);
    return NextThermostat(w, flow_x, mixing_x);
  }

 private:
  double Flow(const RowWeather& w, double flow_x) const {
    if (!state_.pump_on) return 0.0;
    double share = 1.0;
    if (options_.flow_mode == FlowMode::kVariable)
      share = std::clamp(w.g_poa_w_m2 / 800.0, 0.3, 1.0);
    return nominal_flow_kg_s_ * share * (1.0 + 0.01 * flow_x);
  }

  // The original operation, kept bit for bit: irradiance hysteresis, tank
  // gaining tank_gain_fraction of the irradiance while pumping.
  RowOperation NextIrradiance(const RowWeather& w, double flow_x, double mixing_x) {
    state_.since_switch_s += dt_s_;
    if (state_.since_switch_s >= options_.pump_min_dwell_s) {
      if (!state_.pump_on && w.g_poa_w_m2 > options_.pump_on_w_m2) {
        state_.pump_on = true;
        state_.since_switch_s = 0.0;
      } else if (state_.pump_on && w.g_poa_w_m2 < options_.pump_off_w_m2) {
        state_.pump_on = false;
        state_.since_switch_s = 0.0;
      }
    }
    RowOperation row;
    row.mdot_kg_s = Flow(w, flow_x);
    const double gain_k = state_.pump_on ? options_.tank_gain_fraction * w.g_poa_w_m2 * dt_s_ /
                                               options_.tank_heat_capacity_j_m2k
                                         : 0.0;
    t_tank_c_ += gain_k - tank_relax_ * (t_tank_c_ - options_.t_in_base_c);
    row.t_in_c = t_tank_c_ + 0.15 * mixing_x;
    return row;
  }

  // Inlet of the thermostat modes: the tank, after the heat the fluid took
  // in the previous row and the load; or the brine.
  double NextInletC(const RowWeather& w) {
    if (options_.pump_control == PumpControl::kHeatPumpSource) {
      const double target_c = std::clamp(w.t_amb_c - options_.brine_below_ambient_k,
                                         options_.brine_min_c, options_.brine_max_c);
      if (first_row_) brine_smooth_ = LowPass(3600.0, dt_s_, target_c);
      return brine_smooth_.Update(target_c);
    }
    t_tank_c_ += last_q_u_w_ * dt_s_ / (options_.tank_heat_capacity_j_m2k * plant_.area_m2) -
                 tank_relax_ * (t_tank_c_ - options_.t_in_base_c);
    return t_tank_c_;
  }

  bool HeatPumpRuns(const RowWeather& w) const {
    if (options_.pump_control != PumpControl::kHeatPumpSource) return true;
    return w.solar_hour >= options_.heat_pump_from_h && w.solar_hour < options_.heat_pump_to_h;
  }

  // Differential thermostat on the absorber sensor (its value at the row's
  // start) against the inlet, then the absorber over the row.
  RowOperation NextThermostat(const RowWeather& w, double flow_x, double mixing_x) {
    RowOperation row;
    row.t_in_c = NextInletC(w) + 0.15 * mixing_x;
    AbsorberSensorInput in;
    in.g_poa_w_m2 = w.g_poa_w_m2;
    in.t_amb_c = w.t_amb_c;
    in.wind_m_s = w.wind_m_s;
    in.lw_down_w_m2 = w.lw_down_w_m2;
    in.t_in_c = row.t_in_c;
    in.area_m2 = plant_.area_m2;
    in.fluid_cp_j_kgk = plant_.fluid_cp_j_kgk;
    in.dt_s = dt_s_;
    if (first_row_) t_abs_c_ = AbsorberSteadyStateC(options_.absorber, in);
    first_row_ = false;
    state_ =
        StepDifferentialControl(control_, state_, {t_abs_c_, row.t_in_c, HeatPumpRuns(w), dt_s_});
    row.mdot_kg_s = Flow(w, flow_x);
    in.mdot_kg_s = row.mdot_kg_s;
    const AbsorberSensorOutput next = StepAbsorberSensor(options_.absorber, in, t_abs_c_);
    t_abs_c_ = next.t_abs_c;
    last_q_u_w_ = next.q_u_w;
    return row;
  }

  const Plant& plant_;
  const WeatherOptions& options_;
  double dt_s_;
  double nominal_flow_kg_s_;
  double tank_relax_;
  double t_tank_c_;
  LowPass brine_smooth_;
  DifferentialControlParams control_;
  DifferentialControlState state_;
  double t_abs_c_ = 0.0;
  double last_q_u_w_ = 0.0;
  bool first_row_ = true;
};

bool Fail(std::string* why, const std::string& message) {
  if (why != nullptr) *why = message;
  return false;
}

std::string Describe(const char* field, double value, const char* rule) {
  char buf[160];
  std::snprintf(buf, sizeof(buf), "%s = %g: %s", field, value, rule);
  return buf;
}

}  // namespace

double ErbsDiffuseFraction(double clearness_index) {
  const double kt = std::max(0.0, clearness_index);
  if (kt <= 0.22) return 1.0 - 0.09 * kt;
  if (kt <= 0.80) {
    return 0.9511 - 0.1604 * kt + 4.388 * kt * kt - 16.638 * kt * kt * kt +
           12.336 * kt * kt * kt * kt;
  }
  return 0.165;
}

std::string_view DayTypeName(DayType type) {
  switch (type) {
    case DayType::kClear:
      return "clear";
    case DayType::kBrokenClouds:
      return "broken_clouds";
    case DayType::kOvercast:
      return "overcast";
  }
  return "?";
}

std::string_view PumpControlName(PumpControl control) {
  switch (control) {
    case PumpControl::kIrradiance:
      return "irradiance";
    case PumpControl::kDifferential:
      return "differential";
    case PumpControl::kHeatPumpSource:
      return "heat_pump";
  }
  return "?";
}

std::optional<PumpControl> PumpControlFromName(std::string_view name) {
  for (const PumpControl control :
       {PumpControl::kIrradiance, PumpControl::kDifferential, PumpControl::kHeatPumpSource}) {
    if (PumpControlName(control) == name) return control;
  }
  return std::nullopt;
}

namespace {

bool ThermostatOptionsValid(const WeatherOptions& o, std::string* why) {
  if (!(o.pump_dt_off_k >= 0.0 && o.pump_dt_off_k < o.pump_dt_on_k)) {
    return Fail(why,
                Describe("pump_dt_off_k", o.pump_dt_off_k, "must be >= 0 and below pump_dt_on_k"));
  }
  if (!(o.brine_below_ambient_k >= 0.0 && o.brine_below_ambient_k <= 30.0)) {
    return Fail(why,
                Describe("brine_below_ambient_k", o.brine_below_ambient_k, "must be in [0, 30]"));
  }
  if (!(o.brine_min_c >= -20.0 && o.brine_min_c <= o.brine_max_c && o.brine_max_c <= 30.0)) {
    return Fail(why, Describe("brine_min_c", o.brine_min_c,
                              "must be in [-20, brine_max_c] with brine_max_c <= 30"));
  }
  if (!(o.heat_pump_from_h >= 0.0 && o.heat_pump_from_h < o.heat_pump_to_h &&
        o.heat_pump_to_h <= 24.0)) {
    return Fail(why, Describe("heat_pump_from_h", o.heat_pump_from_h,
                              "must be in [0, heat_pump_to_h) with heat_pump_to_h <= 24"));
  }
  const AbsorberSensorParams& a = o.absorber;
  if (!(a.absorbed_fraction >= 0.0 && a.absorbed_fraction <= 1.0 && a.u_front_w_m2k > 0.0 &&
        a.u_back_w_m2k >= 0.0 && a.u_wind_w_m2k >= 0.0 && a.eps_lw >= 0.0 &&
        a.r_internal_m2k_w >= 0.0 && a.r0_fluid_m2k_w >= 0.0 && a.r1_fluid > 0.0 &&
        a.c_j_m2k > 0.0)) {
    return Fail(why, Describe("absorber.u_front_w_m2k", a.u_front_w_m2k,
                              "absorber sensor parameters must be physical (fraction in [0, 1], "
                              "U_front, r1_fluid, C > 0, others >= 0)"));
  }
  return true;
}

}  // namespace

bool WeatherOptions::IsValid(std::string* why) const {
  if (num_days <= 0) return Fail(why, Describe("num_days", num_days, "must be > 0"));
  if (!(step_s >= 1.0 && step_s <= 3600.0) || step_s != std::floor(step_s)) {
    return Fail(why, Describe("step_s", step_s, "must be a whole number of seconds in [1, 3600]"));
  }
  if (!(p_clear >= 0.0 && p_clear <= 1.0)) {
    return Fail(why, Describe("p_clear", p_clear, "must be in [0, 1]"));
  }
  if (!(p_broken >= 0.0 && p_broken <= 1.0 - p_clear + 1e-12)) {
    return Fail(why, Describe("p_broken", p_broken, "must be in [0, 1 - p_clear]"));
  }
  if (!(day_type_persistence >= 0.0 && day_type_persistence < 1.0)) {
    return Fail(why, Describe("day_type_persistence", day_type_persistence, "must be in [0, 1)"));
  }
  if (!(linke_turbidity >= 1.5 && linke_turbidity <= 8.0)) {
    return Fail(why, Describe("linke_turbidity", linke_turbidity, "must be in [1.5, 8]"));
  }
  if (!(t_amb_offset_c >= -30.0 && t_amb_offset_c <= 30.0)) {
    return Fail(why, Describe("t_amb_offset_c", t_amb_offset_c, "must be in [-30, 30]"));
  }
  if (!(flow_kg_s_per_m2 > 0.0 && flow_kg_s_per_m2 <= 0.2)) {
    return Fail(why, Describe("flow_kg_s_per_m2", flow_kg_s_per_m2, "must be in (0, 0.2]"));
  }
  if (!(pump_off_w_m2 >= 0.0 && pump_off_w_m2 < pump_on_w_m2)) {
    return Fail(why,
                Describe("pump_off_w_m2", pump_off_w_m2, "must be >= 0 and below pump_on_w_m2"));
  }
  if (!(pump_min_dwell_s >= 0.0)) {
    return Fail(why, Describe("pump_min_dwell_s", pump_min_dwell_s, "must be >= 0"));
  }
  if (!(t_in_base_c >= 0.0 && t_in_base_c <= 90.0)) {
    return Fail(why, Describe("t_in_base_c", t_in_base_c, "must be in [0, 90]"));
  }
  if (!(tank_heat_capacity_j_m2k > 0.0)) {
    return Fail(why, Describe("tank_heat_capacity_j_m2k", tank_heat_capacity_j_m2k, "must be > 0"));
  }
  if (!(tank_gain_fraction >= 0.0 && tank_gain_fraction <= 1.0)) {
    return Fail(why, Describe("tank_gain_fraction", tank_gain_fraction, "must be in [0, 1]"));
  }
  if (!(tank_load_time_constant_s > 0.0)) {
    return Fail(why,
                Describe("tank_load_time_constant_s", tank_load_time_constant_s, "must be > 0"));
  }
  if (pump_control != PumpControl::kIrradiance) return ThermostatOptionsValid(*this, why);
  return true;
}

std::vector<DayType> DayTypesFor(const WeatherOptions& options) {
  const std::size_t count = static_cast<std::size_t>(options.num_days) + 1;
  std::vector<DayType> types(count);
  if (!options.day_types.empty()) {
    for (std::size_t d = 0; d < count; ++d) {
      types[d] = options.day_types[d % options.day_types.size()];
    }
    return types;
  }
  RandomStream rng(options.seed, kStreamDayTypes);
  auto draw = [&]() {
    const double u = rng.Uniform();
    if (u < options.p_clear) return DayType::kClear;
    if (u < options.p_clear + options.p_broken) return DayType::kBrokenClouds;
    return DayType::kOvercast;
  };
  types[0] = draw();
  for (std::size_t d = 1; d < count; ++d) {
    const bool keep = rng.Uniform() < options.day_type_persistence;
    const DayType fresh = draw();  // drawn in any case to keep the stream aligned
    types[d] = keep ? types[d - 1] : fresh;
  }
  return types;
}

namespace {

// The generated series' rows (every step_s from start_time_s over num_days)
// with every generated channel at 0; *times_s the row times as doubles.
Series EmptyWeatherSeries(const WeatherOptions& options, std::vector<double>* times_s) {
  const auto step = static_cast<std::int64_t>(options.step_s);
  const auto rows = static_cast<std::size_t>(options.num_days * 86400LL / step);
  Series series;
  series.step_s = options.step_s;
  series.time_s.resize(rows);
  times_s->resize(rows);
  for (std::size_t i = 0; i < rows; ++i) {
    series.time_s[i] = options.start_time_s + static_cast<std::int64_t>(i) * step;
    (*times_s)[i] = static_cast<double>(series.time_s[i]);
  }
  for (Channel c : {Channel::kGhiWM2, Channel::kDhiWM2, Channel::kGPoaWM2, Channel::kGPoaDiffuseWM2,
                    Channel::kAoiRad, Channel::kTAmbC, Channel::kWindMS, Channel::kLwDownWM2,
                    Channel::kMdotKgS, Channel::kTInC, Channel::kValid}) {
    series[c].assign(rows, 0.0);
  }
  return series;
}

// Target of the clear-sky index k_c for the day type: clear days vary with
// the haze, broken clouds switch between cloud shadow and edge brightening,
// overcast days follow the deck's thickness (unit-variance processes x).
double ClearSkyIndexTarget(const DayParameters& day, bool sun_hidden, double haze_x, double depth_x,
                           double edge_x, double overcast_x) {
  double k_target = 1.0;
  switch (day.type) {
    case DayType::kClear:
      k_target = std::clamp(day.clear_factor + 0.012 * haze_x, 0.93, 1.03);
      break;
    case DayType::kBrokenClouds:
      k_target = sun_hidden ? std::clamp(0.35 + 0.1 * depth_x, 0.1, 0.6)
                            : std::clamp(1.03 + 0.03 * edge_x, 0.97, 1.1);
      break;
    case DayType::kOvercast:
      k_target = std::clamp(day.overcast_k + 0.07 * overcast_x, 0.05, 0.55);
      break;
  }
  return k_target;
}

// Row i's irradiance: horizontal global (clear sky × k_c, Ineichen–Perez)
// and diffuse (Erbs), and the collector plane's global, diffuse and angle of
// incidence (isotropic sky).
void IrradianceRow(const Plant& plant, const WeatherOptions& options, const SolarPosition& s,
                   double doy, double k_clear_sky, std::size_t i, Series* series) {
  auto& ghi = (*series)[Channel::kGhiWM2];
  auto& dhi = (*series)[Channel::kDhiWM2];
  auto& g_poa = (*series)[Channel::kGPoaWM2];
  auto& g_poa_diffuse = (*series)[Channel::kGPoaDiffuseWM2];
  auto& aoi = (*series)[Channel::kAoiRad];
  const double cos_zenith = std::cos(s.zenith_rad);
  ClearSkyInput cs_in;
  cs_in.zenith_rad = s.zenith_rad;
  cs_in.day_of_year = doy;
  cs_in.elevation_m = plant.elevation_m;
  cs_in.linke_turbidity = options.linke_turbidity;
  const ClearSkyIrradiance clear = ClearSkyIneichenPerez(cs_in);
  const double ghi_w_m2 = k_clear_sky * clear.ghi_w_m2;
  double dhi_w_m2 = ghi_w_m2;
  if (cos_zenith >= 0.05) {
    const double kt = ghi_w_m2 / (ExtraterrestrialNormalWM2(doy) * cos_zenith);
    dhi_w_m2 = ErbsDiffuseFraction(kt) * ghi_w_m2;
  }
  ghi[i] = ghi_w_m2;
  dhi[i] = std::min(dhi_w_m2, ghi_w_m2);

  // Collector plane.
  const double aoi_rad =
      AngleOfIncidenceRad(s.zenith_rad, s.azimuth_rad, plant.tilt_rad, plant.azimuth_rad);
  IsotropicSkyInput poa_in;
  poa_in.ghi_w_m2 = ghi[i];
  poa_in.dhi_w_m2 = dhi[i];
  poa_in.zenith_rad = s.zenith_rad;
  poa_in.aoi_rad = aoi_rad;
  poa_in.tilt_rad = plant.tilt_rad;
  poa_in.ground_albedo = plant.ground_albedo;
  const PoaComponents poa = TransposeIsotropicSky(poa_in);
  g_poa[i] = poa.global_w_m2();
  g_poa_diffuse[i] = poa.sky_diffuse_w_m2 + poa.ground_diffuse_w_m2;
  aoi[i] = aoi_rad;
}

// Long-wave irradiance on the plane, W/m²: Brunt clear-sky emissivity with a
// cloud-cover increase for the sky part, ground at air temperature, each
// weighted by its view factor from the tilted plane.
double LongWaveDownWM2(double relative_humidity, double cover, double t_amb_c, double tilt_rad) {
  const double vapour_hpa = relative_humidity * SaturationVapourPressureHpa(t_amb_c);
  const double eps_sky = CloudySkyEmissivity(BruntClearSkyEmissivity(vapour_hpa), cover);
  return LongWaveOnPlaneWM2(eps_sky, t_amb_c, tilt_rad);
}

}  // namespace

Series GenerateWeather(const Plant& plant, const WeatherOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) {
    std::fprintf(stderr, "GenerateWeather: invalid WeatherOptions: %s\n", why.c_str());
    std::abort();
  }
  const double dt_s = options.step_s;
  std::vector<double> times_s;
  Series series = EmptyWeatherSeries(options, &times_s);
  const std::size_t rows = series.size();

  // Sun positions for all rows at once.
  std::vector<SolarPosition> sun;
  ComputeSolarPositions(times_s, SiteAtStandardPressure(plant), &sun);

  const std::vector<DayType> day_types = DayTypesFor(options);
  const double first_day =
      LocalSolarDayNumber(times_s.empty() ? 0.0 : times_s[0], plant.longitude_rad);

  auto& g_poa = series[Channel::kGPoaWM2];
  auto& t_amb = series[Channel::kTAmbC];
  auto& wind = series[Channel::kWindMS];
  auto& lw_down = series[Channel::kLwDownWM2];
  auto& mdot = series[Channel::kMdotKgS];
  auto& t_in = series[Channel::kTInC];
  auto& valid = series[Channel::kValid];

  RandomStream day_rng(options.seed, kStreamDayParameters);
  RandomStream cloud_rng(options.seed, kStreamClouds);
  RandomStream temp_rng(options.seed, kStreamTemperature);
  RandomStream wind_rng(options.seed, kStreamWind);
  RandomStream pump_rng(options.seed, kStreamPump);
  RandomStream tank_rng(options.seed, kStreamTank);

  // Sky processes (unit-variance AR(1) each).
  UnitAr1 haze(2.0 * 3600.0, dt_s, &cloud_rng);         // clear-day slow variation
  UnitAr1 cloud_depth(20.0 * 60.0, dt_s, &cloud_rng);   // optical depth under cumulus
  UnitAr1 edge(3.0 * 60.0, dt_s, &cloud_rng);           // brightening at cloud edges
  UnitAr1 overcast_var(40.0 * 60.0, dt_s, &cloud_rng);  // overcast deck thickness
  LowPass k_smooth(20.0, dt_s, 1.0);                    // cloud edge passage, ~20 s
  bool sun_hidden = false;
  // Temperature and wind.
  UnitAr1 t_anomaly(3.0 * kSecondsPerDay, dt_s, &temp_rng);
  UnitAr1 t_noise(10.0 * 60.0, dt_s, &temp_rng);
  UnitAr1 wind_slow(3600.0, dt_s, &wind_rng);
  UnitAr1 wind_gust(120.0, dt_s, &wind_rng);
  // Day-type dependent levels change smoothly across local midnight.
  LowPass half_range_smooth(3.0 * 3600.0, dt_s, 6.0);
  LowPass wind_median_smooth(3.0 * 3600.0, dt_s, 2.0);
  LowPass humidity_smooth(3.0 * 3600.0, dt_s, 0.6);
  LowPass cover_smooth(3.0 * 3600.0, dt_s, 0.05);
  // Operation.
  UnitAr1 flow_noise(5.0 * 60.0, dt_s, &pump_rng);
  UnitAr1 tank_mixing(10.0 * 60.0, dt_s, &tank_rng);
  PlantOperation operation(plant, options, dt_s);

  const double abs_lat_deg = std::abs(RadToDeg(plant.latitude_rad));
  const double t_annual_c = 28.0 - 0.38 * abs_lat_deg;
  const double t_season_k = 0.22 * abs_lat_deg * (plant.latitude_rad >= 0.0 ? 1.0 : -1.0);

  double current_day = std::nan("");
  DayParameters day;
  bool first_row = true;
  for (std::size_t i = 0; i < rows; ++i) {
    const double time_s = times_s[i];
    const SolarPosition& s = sun[i];

    // New local solar day: draw its parameters.
    const double day_number = LocalSolarDayNumber(time_s, plant.longitude_rad);
    if (day_number != current_day) {
      const auto index = static_cast<std::size_t>(
          std::clamp(day_number - first_day, 0.0, static_cast<double>(day_types.size() - 1)));
      day = DrawDayParameters(day_types[index], &day_rng);
      current_day = day_number;
      if (first_row) {
        // Start the smoothed levels at the first day's values.
        half_range_smooth = LowPass(3.0 * 3600.0, dt_s, day.t_amb_half_range_k);
        wind_median_smooth = LowPass(3.0 * 3600.0, dt_s, day.wind_median_m_s);
        humidity_smooth = LowPass(3.0 * 3600.0, dt_s, day.relative_humidity);
        cover_smooth = LowPass(3.0 * 3600.0, dt_s, day.sky_cloud_cover);
        first_row = false;
      }
    }

    // Clear-sky index k_c of the day type's cloud process. Every process
    // advances on every row so that the streams do not depend on day types.
    const double haze_x = haze.Next();
    const double depth_x = cloud_depth.Next();
    const double edge_x = edge.Next();
    const double overcast_x = overcast_var.Next();
    const double u_switch = cloud_rng.Uniform();
    const double tau_hidden_s = day.cloud_fraction * day.cycle_s;
    const double tau_visible_s = (1.0 - day.cloud_fraction) * day.cycle_s;
    if (sun_hidden) {
      if (u_switch < 1.0 - std::exp(-dt_s / tau_hidden_s)) sun_hidden = false;
    } else {
      if (u_switch < 1.0 - std::exp(-dt_s / tau_visible_s)) sun_hidden = true;
    }
    const double k_target =
        ClearSkyIndexTarget(day, sun_hidden, haze_x, depth_x, edge_x, overcast_x);
    const double k_clear_sky = std::clamp(k_smooth.Update(k_target), 0.0, 1.1);

    const double doy = DayOfYear(time_s);
    IrradianceRow(plant, options, s, doy, k_clear_sky, i, &series);
    // Ambient temperature: season + offset + anomaly + diurnal wave + noise.
    const double season_c = t_annual_c + t_season_k * std::cos(kTwoPi * (doy - 201.0) / 365.2425);
    const double half_range_k = half_range_smooth.Update(day.t_amb_half_range_k);
    const double diurnal_k = half_range_k * std::cos(s.hour_angle_rad - DegToRad(45.0));
    const double t_amb_c = season_c + options.t_amb_offset_c + 3.0 * t_anomaly.Next() + diurnal_k +
                           0.2 * t_noise.Next();
    t_amb[i] = t_amb_c;

    // Wind: median × afternoon factor × slow log-normal × gusts.
    const double afternoon = 1.0 + 0.25 * std::cos(s.hour_angle_rad - DegToRad(30.0));
    wind[i] = std::max(0.0, wind_median_smooth.Update(day.wind_median_m_s) * afternoon *
                                std::exp(0.35 * wind_slow.Next()) *
                                std::exp(0.25 * wind_gust.Next() - 0.5 * 0.25 * 0.25));

    // Long-wave irradiance on the plane: Brunt clear-sky emissivity with a
    // cloud-cover increase for the sky part, ground at air temperature.
    const double relative_humidity = humidity_smooth.Update(day.relative_humidity);
    const double cover = cover_smooth.Update(day.sky_cloud_cover);
    lw_down[i] = LongWaveDownWM2(relative_humidity, cover, t_amb_c, plant.tilt_rad);

    // Pump and inlet.
    RowWeather row_weather;
    row_weather.g_poa_w_m2 = g_poa[i];
    row_weather.t_amb_c = t_amb_c;
    row_weather.wind_m_s = wind[i];
    row_weather.lw_down_w_m2 = lw_down[i];
    row_weather.solar_hour = SolarHour(s.hour_angle_rad);
    const double flow_x = flow_noise.Next();
    const RowOperation op = operation.Next(row_weather, flow_x, tank_mixing.Next());
    mdot[i] = op.mdot_kg_s;
    t_in[i] = op.t_in_c;

    valid[i] = 1.0;
  }
  return series;
}

}  // namespace pvtwin

#include "core/common/physical_ranges.h"

#include <cmath>

namespace pvtwin {

namespace {

// A range given as factors of the plant's value (relative_to_plant in
// params.h), or absolute.
struct Entry {
  double lower;
  double upper;
  bool relative;
  std::string_view source;
};

// Per m² of collector, in the normalisation of params.h. An entry that says
// "Table 3" keeps the paper's range: it is already physically wide, or no
// published range is wider.
Entry EntryOf(Param p) {
  switch (p) {
    case Param::kAreaM2:
      return {0.5, 1.5, true,
              "Table 3: A_PVT also carries the optical efficiency's error; an aperture is "
              "0.85-0.97 of the gross area (ISO 9806 test reports)"};
    case Param::kEpsPvt:
      return {0.0, 0.95, false,
              "long-wave emittance of glass and of a PV module's front glass 0.84-0.94 "
              "(Duffie & Beckman, Solar Engineering of Thermal Processes, 4th ed., ch. 4; "
              "0.88 in their collector examples); 0: the exchange is all in U_front"};
    case Param::kEtaPvRef:
      return {0.04, 0.25, false,
              "module efficiency at STC: amorphous Si about 6 % to heterojunction c-Si about "
              "23 % (Green et al., Solar cell efficiency tables, Prog. Photovolt.)"};
    case Param::kFTh:
      return {0.5, 1.2, false,
              "Table 3: the collector efficiency factor F' is 0.7-1.0 (Duffie & Beckman ch. 6), "
              "F_th also carries irradiance errors"};
    case Param::kUFrontWM2K:
      return {1e-3, 1e3, false,
              "Table 3: uncovered and PVT collectors' front loss with wind 5-40 W/m2K "
              "(ISO 9806 test reports) lies well inside"};
    case Param::kUBackWM2K:
      return {1e-3, 1e3, false,
              "Table 3: 50 mm of insulation loses about 0.7 W/m2K (Duffie & Beckman ch. 6), "
              "a bare back up to about 20"};
    case Param::kUCollWM2K:
      return {1e-3, 1e3, false, "Table 3: wider than any bond between PV and absorber"};
    case Param::kR0FluidM2KW:
      return {1e-4, 1e3, false, "Table 3: wider than any absorber-to-fluid resistance"};
    case Param::kR1Fluid:
      return {1e-2, 1e2, false, "Table 3 (dimensionless, see params.h)"};
    case Param::kCPvJM2K:
    case Param::kCCollJM2K:
      return {1e3, 1e7, false,
              "Table 3: 3.2 mm of glass holds 6.7 kJ/m2K, a filled collector 10-60 kJ/m2K "
              "(ISO 9806 effective heat capacity; 42 kJ/m2K at htw saar)"};
    case Param::kRRefWind:
      return {1e-2, 1e2, false, "Table 3"};
    case Param::kNWind:
      return {0.3, 1.2, false,
              "Table 3: forced convection goes with Re^0.5 (laminar) to Re^0.8 (turbulent)"};
    case Param::kUWindWM2K:
      return {1e-2, 1e2, false, "Table 3: ISO 9806 wind coefficients c3 of 0-5 W/m2K/(m/s)"};
    case Param::kPvTempCoeffPerK:
      return {-0.0055, -0.0015, false,
              "module datasheets: a-Si about -0.2 %/K, CdTe -0.28 %/K, c-Si -0.35 to -0.5 %/K"};
    case Param::kPvIrrCoeffM2W:
      return {0.5, 1.5, true, "Table 3: no published range is wider"};
    case Param::kTransportDelayS:
      return {0.0, 900.0, false, "Table 3"};
    case Param::kUPipeWM2K:
    case Param::kNFlow:
    case Param::kPLimitWM2:
    case Param::kShadeAzimuthRad:
    case Param::kShadeWidthRad:
    case Param::kShadeElevationRad:
    case Param::kShadeMismatch:
    case Param::kSoilingPerDay:
    case Param::kClockOffsetS:
    case Param::kIrradianceBias:
    case Param::kPipePlugKgM2:
    case Param::kPipeMixKgM2:
    case Param::kIamB0Fit: {
      const ParamInfo& info = Info(p);
      return {info.lower, info.upper, false,
              "the effect's own range, already its physically plausible one (params.cc)"};
    }
    case Param::kSkyCloudOffset:
      return {-1.0, 1.0, false,
              "a cloud fraction lies in 0-1, so its offset from the logged sky's in -1-1"};
    case Param::kCount:
      break;
  }
  return {std::nan(""), std::nan(""), false, ""};
}

}  // namespace

PhysicalRange PhysicalRangeOf(Param p, const Plant& plant) {
  const Entry e = EntryOf(p);
  if (!e.relative) return {e.lower, e.upper, e.source};
  // The plant's value: the relative parameters start at the factor 1.
  const double reference = ResolvedInfo(p, plant).start / Info(p).start;
  const double a = e.lower * reference;
  const double b = e.upper * reference;
  return {std::fmin(a, b), std::fmax(a, b), e.source};
}

ParamInfo WidenedInfo(Param p, const Plant& plant) {
  ParamInfo info = ResolvedInfo(p, plant);
  const PhysicalRange range = PhysicalRangeOf(p, plant);
  info.lower = std::fmin(info.lower, range.lower);
  info.upper = std::fmax(info.upper, range.upper);
  return info;
}

}  // namespace pvtwin

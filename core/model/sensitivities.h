// The model run with forward sensitivities: Simulate's outputs P_el, Q_u and
// T_PV per row together with their exact derivatives with respect to a list
// of parameters, for identification's Jacobian (core/fit/identification.h).
//
// Hand-chained through each row (forward mode): the derivatives of the row
// terms (g_front with the paper's wind form 'w', g_fluid of eq. 2.7, q_sun,
// η_PV of eq. 2.4, the sky loss of eq. 2.6), of the network linearised about
// T_PV, and of the exact step (core/physics/rc_network_tangent.h), started
// from the derivatives of the previous row's end state, or at a restart row
// from those of the steady state of its inputs (paper 2.2).
//
// The linearisation point is differentiated as the run computes it, pass by
// pass: the first pass linearises about the extrapolation of the previous
// two rows' T_PV (whose derivatives are carried along), each further pass
// about the previous pass's step-mean T_PV (d G_PV/d T_lin = q_rad'',
// d S_PV/d T_lin = q_rad''·T_lin, plus q_abs' where the Q_abs slope stays
// explicit, see Linearise). These are the derivatives of Simulate's own
// arithmetic for its number of passes, which central differences of
// Simulate confirm to about 1e-9 of a column's scale
// (tests/unit/test_model_sensitivities.cc). The values P_el, Q_u and T_PV
// are Simulate's to the bit, on every variant and effect the tests run: the
// same arithmetic in the same order (no -ffast-math, and no FMA contraction
// at x86-64's baseline ISA), so that a caller may take a run with
// sensitivities for a plain run of the same parameters (identification's
// objective does). The linearisation point's own dependence is not
// negligible: left out, the same tests find errors of 1e-4 to 5e-2 of a
// column's scale (the step-mean of a capacitive node depends on the point,
// and an explicit Q_abs slope depends on it to first order). The pass count
// changes with the parameters in steps; there Simulate jumps (far below
// kNodeToleranceK) and has no derivative.
//
// Supported: every network shape, and effect extensions that change the
// run's per-row inputs (ModelExtension::transform_drivers), electric effects
// included: the run takes the inputs as the hooks leave them, so the
// columns of the parameters no hook reads stay exact. The parameters a hook
// reads (HookParams) have no column; the caller differences them (a mixed
// Jacobian, core/fit/identification.cc). An extension that transforms the
// outputs affinely (ModelExtension::outputs_affine: transport_delay's sensor
// behind a pipe) gets the derivatives pushed through its hook: with y the
// outputs and d a column, T(y + s·d) − T(y) = s·T'd exactly for an affine T,
// one hook call per column. Parameters the variant does not use get zero
// columns.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/common/model_data.h"
#include "core/common/params.h"

namespace pvtwin {

// Where a caller takes the derivatives straight into a matrix of its own
// (identification's Jacobian) instead of SimSensitivities' dp_el_w,
// dq_th_w and dt_pv_c: scaled and at its own rows, which saves their
// storage and a copy. Column-major, `stride` doubles per column.
struct SensitivitySink {
  double* base = nullptr;
  std::size_t stride = 0;
  // Rows per output: P_el's derivatives at rows 0.., Q_u's at `rows`..,
  // T_PV's at 2·rows.. (when SimSensitivities::t_pv_derivatives).
  std::size_t rows = 0;
  // Per simulated row: its row in the sink, or −1 (not written).
  std::span<const std::int32_t> position;
  // Per parameter of wrt: the sink's column, and the column's factor.
  std::span<const std::size_t> column;
  std::span<const double> column_factor;
  // P_el and Q_u: (d·value_factor)·column_factor; T_PV:
  // (t_pv_factor·d)·column_factor.
  double value_factor = 1.0;
  double t_pv_factor = 1.0;
  // Out, per parameter of wrt: 0 once a value written is not finite.
  std::vector<std::uint8_t> finite;
};

struct SimSensitivities {
  // Set by the caller: false leaves dt_pv_c empty when no extension
  // transforms the outputs (an objective without T_PV: a third fewer
  // derivatives written).
  bool t_pv_derivatives = true;
  // Set by the caller: threads the columns are split over (at most two; a
  // run too small to gain, or of a one-node variant, stays on one). The
  // results are the same to the bit on any number.
  int threads = 1;
  // Set by the caller: the derivatives go to this sink (the values stay
  // here), unless an extension transforms the outputs, which reads them
  // here. in_sink says which.
  SensitivitySink* sink = nullptr;
  bool in_sink = false;

  std::vector<Param> wrt;
  std::size_t rows = 0;
  // Simulate's outputs (NaN where Simulate's are).
  std::vector<double> p_el_w, q_th_w, t_pv_c;
  // d output[i] / d wrt[j] at index j·rows + i (one column per parameter,
  // column-major): W (or K) per unit of the parameter (params.h). dt_pv_c
  // is empty when t_pv_derivatives is false and no extension transforms the
  // outputs; all three are empty when in_sink.
  std::vector<double> dp_el_w, dq_th_w, dt_pv_c;

  const double* DPEl(std::size_t j) const { return dp_el_w.data() + j * rows; }
  const double* DQTh(std::size_t j) const { return dq_th_w.data() + j * rows; }
  const double* DTPv(std::size_t j) const { return dt_pv_c.data() + j * rows; }

  // With an extension that transforms the outputs: the collector node's and
  // the outlet's temperature before the transform, with their derivatives
  // (same layout), which the transform reads.
  std::vector<double> t_coll_c, t_out_c, dt_coll_c, dt_out_c;

  // Work space of the extensions' hooks, and the outputs pushed through
  // transform_outputs (kept between runs).
  SimOutputs hook_work, pushed;
};

// Rows × columns from which a run of a two-node variant with
// SimSensitivities::threads = 2 splits its columns over two threads
// (below, the helper's start and the values computed twice outweigh the
// gain; a one-node variant's columns are too cheap at any size).
inline constexpr std::size_t kSensitivitySplitWork = 100000;

// Most parameters one sensitivity run differentiates for.
std::size_t MaxSensitivityParams();

// The parameters the spec's extension hooks read: each extension's own and
// the base model's it declares (ModelExtension::reads_base_params). A run
// with sensitivities has no column for them.
std::vector<Param> HookParams(const ModelSpec& spec);

// `params` without the HookParams of `spec`: the ones a run with
// sensitivities can differentiate for.
std::vector<Param> WithoutHookParams(const ModelSpec& spec, std::span<const Param> params);

// True when SimulateSensitivities handles `spec` with these parameters;
// otherwise *why (may be null) says why (the caller then takes finite
// differences of Simulate).
bool SensitivitiesSupported(const ModelSpec& spec, std::span<const Param> wrt, std::string* why);

// Runs the model at `params` with the derivatives of its outputs with
// respect to `wrt`. False (and *why) when not supported; *out is then
// unchanged. Reusing *out between calls avoids any allocation.
bool SimulateSensitivities(const Drivers& drivers, const ParamVector& params,
                           std::span<const Param> wrt, SimSensitivities* out,
                           std::string* why = nullptr);

}  // namespace pvtwin

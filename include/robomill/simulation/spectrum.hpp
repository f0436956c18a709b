#pragma once
// The amplitude spectrum moved to the monitoring module (issue 22: one
// detector for simulated and recorded signals, monitoring/spectrum.hpp);
// these names keep the simulator's callers (response metrics, roughness, the
// simulate command) unchanged.

#include "robomill/monitoring/spectrum.hpp"

namespace robomill::simulation {

using monitoring::amplitude_spectrum;
using monitoring::AmplitudeSpectrum;
using monitoring::peak_frequency_hz;
using monitoring::resonance_frequency_hz;

}  // namespace robomill::simulation

#pragma once
// `robomill simulate` of a job: the nonlinear, regenerative time-domain
// simulation of 002 §3 (docs/simulation.md). The structure (modal model,
// 002's 1/2-DOF fixations, the reduced 6-D robot model of 002 Eq 23, or
// rigid) is driven by the cutting forces of the teeth, whose chips come from
// the swept-surface memory; the response gives the static deviation,
// overshoot, settling time, first frequency and the chatter verdict, and the
// steady window's spectrum. SI units unless a field says otherwise.

#include <Eigen/Core>
#include <array>

#include "robomill/job/job.hpp"
#include "robomill/simulation/response_metrics.hpp"
#include "robomill/simulation/simulator.hpp"
#include "robomill/simulation/spectrum.hpp"
#include "robomill/simulation/structure.hpp"

namespace robomill::analysis {

struct TimeSimulation {
  /// The structure the forces drive (simulation.model), with its description.
  simulation::LinearStructure structure;
  Eigen::VectorXd natural_frequencies_hz;  ///< of `structure`
  /// Steps per tooth period: the job's, or the default raised to what the
  /// structure, the engaged arc and the process damping need.
  int steps_per_tooth = 0;
  int axial_elements = 0;               ///< simulation.axial_elements, or as `forces`
  simulation::SimulationResult result;  ///< the recorded run (tool frame)
  /// What the response was analysed with (the chatter verdict's settings).
  simulation::ResponseOptions response_options;
  simulation::ResponseMetrics metrics;
  /// Amplitude spectra (Hann window) of the steady window's forces fx, fy,
  /// fz (N) and displacements x, y, z — the displacements sampled in mm, so
  /// their amplitudes are in mm.
  std::array<simulation::AmplitudeSpectrum, 3> force_spectra_n;
  std::array<simulation::AmplitudeSpectrum, 3> displacement_spectra_mm;
  int max_teeth_cutting = 0;  ///< the most teeth cutting at once over the run
  double elapsed_s = 0.0;     ///< the structure, the run and its metrics
};

/// The job's simulation. Needs the tool, cutting, process and simulation
/// sections (and the robot with a posture for model reduced6d); throws
/// InputError naming the field, and the value that would work, when the step
/// is too coarse for the highest mode, the engaged arc or the process
/// damping, when the cutter never reaches the part, or when the run is too
/// short for the metrics.
TimeSimulation time_simulation(const job::Job& job);

}  // namespace robomill::analysis

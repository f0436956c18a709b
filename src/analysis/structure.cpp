#include "robomill/analysis/structure.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "robomill/core/error.hpp"
#include "robomill/io/frf_csv.hpp"
#include "robomill/io/uff58.hpp"
#include "robomill/robot/joint_dynamics.hpp"
#include "robomill/robot/kinematics.hpp"

namespace robomill::analysis {

std::vector<dynamics::Frf> load_measured_frfs(const job::Job& job) {
  std::vector<dynamics::Frf> frfs;
  for (const job::FrfFileSpec& spec : job.frf_files) {
    try {
      if (spec.format == job::FrfFileSpec::Format::csv) {
        io::FrfCsvOptions options;
        options.kind = *spec.kind;
        options.scale_to_si = spec.scale_to_si;
        options.response_axis = *spec.response_axis;
        options.reference_axis = *spec.reference_axis;
        frfs.push_back(io::read_frf_csv(spec.file, options));
      } else {
        io::Uff58ReadOptions options;
        if (spec.kind) {
          options.kind = spec.kind;
          options.ordinate_scale_to_si = spec.scale_to_si;
        }
        options.response_axis = spec.response_axis;
        options.reference_axis = spec.reference_axis;
        for (io::UffFrf& entry : read_uff58(spec.file, options))
          frfs.push_back(std::move(entry.frf));
      }
    } catch (const InputError& error) {
      throw InputError(spec.path + ".file", spec.line, error.what());
    } catch (const std::invalid_argument& error) {
      throw InputError(spec.path + ".file", spec.line, error.what());
    }
  }
  return frfs;
}

StructureFit fit_structure(const job::Job& job, const std::vector<dynamics::Frf>& measured) {
  dynamics::ModalFitOptions options;
  for (const job::FitSettings::Band& band : job.fit.bands)
    options.bands.push_back({band.low_hz, band.high_hz, band.max_order});
  if (job.fit.max_order > 0)
    options.max_order = job.fit.max_order;

  std::vector<dynamics::Frf> direct;
  std::vector<dynamics::ModalFit> fits;
  std::vector<dynamics::Mode> modes;
  for (const dynamics::Frf& frf : measured) {
    if (frf.response_axis != frf.reference_axis)
      continue;
    dynamics::ModalFit fit;
    try {
      fit = dynamics::fit_modes({frf}, options);
    } catch (const std::invalid_argument& error) {
      throw InputError("dynamics.fit", 0,
                       fmt::format("fitting H{0}{0}: {1}", "xyz"[frf.response_axis], error.what()));
    } catch (const NumericalError& error) {
      throw NumericalError(
          fmt::format("fitting H{0}{0}: {1}", "xyz"[frf.response_axis], error.what()));
    }
    for (const dynamics::FittedMode& mode : fit.modes) {
      if (!(mode.stiffness_n_per_m > 0.0))
        continue;  // no driving-point constant: cannot place it at the tip
      modes.push_back(dynamics::directional_mode(frf.response_axis, mode.natural_frequency_hz,
                                                 mode.damping_ratio, mode.stiffness_n_per_m));
    }
    direct.push_back(frf);
    fits.push_back(std::move(fit));
  }
  if (direct.empty()) {
    throw InputError("dynamics.frf", 0,
                     "no driving-point FRF (response = reference direction) to fit modes to");
  }
  if (modes.empty())
    throw NumericalError("the modal fit found no mode with a positive modal stiffness");
  return {std::move(direct), std::move(fits), dynamics::ModalModel(std::move(modes))};
}

dynamics::ModalModel structure_modes(const job::Job& job) {
  switch (job.dynamics_source) {
    case job::Job::DynamicsSource::table:
    case job::Job::DynamicsSource::postures:  // interpolated into job.modes by the parser
      return job::modal_model(job);
    case job::Job::DynamicsSource::fit:
      return fit_structure(job, load_measured_frfs(job)).modes;
    case job::Job::DynamicsSource::robot: {
      if (!job.robot)
        throw InputError("dynamics.from_robot", 0, "needs a robot: section");
      if (job.robot->posture_rad.empty())
        throw InputError("robot.posture", 0,
                         "required with dynamics.from_robot: the posture whose modes to use");
      try {
        const robot::RobotModel model(job.robot->description);
        const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(
            job.robot->posture_rad.data(),
            static_cast<Eigen::Index>(job.robot->posture_rad.size()));
        // The modes along the tool's own axes at that posture (x the feed,
        // z the tool axis: the robot's tool frame must be set up so).
        return robot::tool_tip_modal_model(model, q,
                                           robot::tool_pose(model, q).linear().transpose());
      } catch (const std::invalid_argument& error) {
        throw InputError("robot", 0, error.what());
      }
    }
    case job::Job::DynamicsSource::frf:
      break;
  }
  throw InputError("dynamics.use", 0,
                   "is 'frf': the measured FRFs are used directly, which gives no modes; this "
                   "analysis needs modes (dynamics.use: fit or table)");
}

}  // namespace robomill::analysis

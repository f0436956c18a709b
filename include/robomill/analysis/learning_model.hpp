#pragma once
// The job's stability limit as a function of its uncertain inputs, fast
// enough to be evaluated a few hundred thousand times by the sampler of
// `robomill learn` (issue 35; docs/learning.md, "The model").
//
// `stability` and `advise` make a draw by re-reading the job with the drawn
// values (analysis/job_draws.hpp: exact for any field, about a millisecond a
// draw). Learning evaluates the model for every particle at every Metropolis
// step, so this model sets the fields a variable can vary directly: the
// linear law's coefficients (cutting.Ktc, Krc, Kac, Kte, Kre, Kae; A0 is
// linear in the shear coefficients, so the cut is averaged once,
// stability::MeanCuttingStiffnessBasis) and the modal table's fn, zeta and
// k (dynamics.modes[i].*: the mode's shape e·ωn/√k). The zero-order limit
// (stability/zero_order.hpp, Altintas & Budak 1995) is then solved on a
// chatter-frequency grid placed around the drawn modes. The construction
// checks, on two prior draws, that these settings give the very modes and
// coefficients the job re-read with the drawn values gives; a variable on any
// other field is refused by name.
//
// Values are in the variables' own terms: SI for `mode: value`, the factor
// for `mode: scale` (job::UncertaintySettings).

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "robomill/cutting/cutting_law.hpp"
#include "robomill/dynamics/modal_model.hpp"
#include "robomill/job/job.hpp"
#include "robomill/stability/zero_order.hpp"
#include "robomill/tool/tool.hpp"
#include "robomill/uncertainty/distribution.hpp"

namespace robomill::analysis {

/// The stability limit of a job with its uncertain inputs set: zero-order
/// by default, a time-domain method's with learn.method.
class LearningModel {
 public:
  /// The model of `job` (a tool, a linear cutting law, a process, a modal
  /// table, a stability section and an uncertainty section whose variables
  /// all have distributions). Throws InputError naming the section or the
  /// variable (its line) when the job does not fit.
  explicit LearningModel(const job::Job& job);

  /// The variables' names and prior distributions, in the job's order.
  const std::vector<std::string>& names() const noexcept { return names_; }
  const std::vector<uncertainty::Distribution>& priors() const noexcept { return priors_; }
  int dimension() const noexcept { return static_cast<int>(names_.size()); }

  /// The variables' values for standard-normal coordinates w (the sampler's):
  /// x_j = F_j⁻¹(Φ(z_j)), z = L w with L the correlation's Cholesky factor
  /// (z = w for independent variables).
  Eigen::VectorXd values_of(const Eigen::VectorXd& w) const;

  /// The linear law with values x set; nullopt when x gives no structure.
  std::optional<cutting::LinearLaw> law_of(const Eigen::VectorXd& x) const;

  /// The job's own values: 1 for a scale variable, the nominal value (SI) otherwise.
  Eigen::VectorXd nominal_values() const;

  /// The limits at `speeds_rad_s` for values x at place `place`, written to
  /// `out` (same size). Returns false, writing nothing, when x gives no
  /// structure (a damping ratio ≥ 1, a non-positive stiffness or frequency,
  /// a negative coefficient). Thread-safe.
  bool limits(const Eigen::VectorXd& x, int place, int cut, std::span<const double> speeds_rad_s,
              std::span<stability::ZeroOrderLimit> out) const;
  /// Of the job's own cut (cut 0).
  bool limits(const Eigen::VectorXd& x, int place, std::span<const double> speeds_rad_s,
              std::span<stability::ZeroOrderLimit> out) const {
    return limits(x, place, 0, speeds_rad_s, out);
  }
  /// At the first place (the job's own structure).
  bool limits(const Eigen::VectorXd& x, std::span<const double> speeds_rad_s,
              std::span<stability::ZeroOrderLimit> out) const {
    return limits(x, 0, speeds_rad_s, out);
  }

  /// Where the structure is known: for a robot (dynamics.from_robot) the
  /// postures (joint angles, rad) robot.posture, then every experiment's
  /// posture and learn.places, each once, in that order; otherwise the one
  /// structure of the modal table (an empty posture).
  const std::vector<std::vector<double>>& places() const noexcept { return places_; }
  /// The place of a posture (exactly one of places()); 0 for an empty one.
  int place_of(const std::vector<double>& posture_rad) const;
  /// The posture of job.experiments[index] (its `posture`, its `position`'s
  /// inverse kinematics, or empty: robot.posture's); empty without a robot.
  const std::vector<double>& experiment_posture(std::size_t index) const {
    return experiment_postures_.at(index);
  }

  /// The cuts whose limits are solved: 0 the job's process, then each other
  /// radial depth and direction of the experiments (`ae`, `direction`).
  int cut_of(const job::Experiment& test) const;

  /// The structure's modes at `place` for values x (mass-normalized shapes
  /// in the tool frame); false when x gives no structure.
  bool modes(const Eigen::VectorXd& x, int place, std::vector<dynamics::Mode>& out) const;
  bool robot() const noexcept { return !robot_places_.empty(); }

  int teeth() const noexcept { return teeth_; }
  /// The deepest limit solved for (m): 1.25 × the deeper of
  /// stability.depth_max and the deepest experiment; beyond it a limit is
  /// reported as not limited. No test or candidate is deeper than that
  /// depth, where such a limit's probit gives chatter a probability of
  /// at most Φ(−0.2 a_lim/σ) ≤ Φ(−3.9) at the default spreads, far below the
  /// mislabel chance ε/2 that a limit beyond reach is given instead.
  double search_depth_m() const noexcept { return search_depth_m_; }

 private:
  /// A field a variable sets.
  struct Setter {
    enum class Field {
      ktc,
      krc,
      kac,
      kte,
      kre,
      kae,
      fn,
      zeta,
      k,
      joint_stiffness,
      robot_damping
    } field = Field::ktc;
    int mode = -1;       ///< the modal table's row (fn, zeta, k) or the joint
    int variable = 0;    ///< which value sets it
    double nominal = 0;  ///< the job's value (SI)
    bool scale = false;  ///< value × nominal, else the value itself
  };
  struct Structure {
    cutting::LinearLaw law;
    std::vector<job::ModeSpec> modes;  ///< the modal table
    Eigen::VectorXd joint_stiffness;   ///< a robot's Kq (N·m/rad)
    double robot_damping_ratio = 0.0;  ///< a robot's modal damping ratio
  };
  /// A robot posture's joint-space mass matrix M(q) and the tip's linear
  /// Jacobian in the tool frame, R·Jv: the modes there follow from Kq alone
  /// (K φ = ω² M φ, tip shape R Jv φ; joint_dynamics.hpp).
  struct RobotPlace {
    Eigen::MatrixXd mass;
    Eigen::Matrix<double, 3, Eigen::Dynamic> tip_jacobian;
  };
  /// The structure's modes at `place` (the modal table, or the robot's).
  bool modes_at(const Structure& structure, int place, std::vector<dynamics::Mode>& modes) const;
  void set_up_robot(const job::Job& job);
  void set_up_cuts(const job::Job& job);
  /// The law and modes with the values set; false when they are not physical.
  bool apply(const Eigen::VectorXd& x, Structure& out) const;
  void check_against_the_job(const job::Job& job) const;

  std::vector<std::string> names_;
  std::vector<uncertainty::Distribution> priors_;
  std::optional<Eigen::MatrixXd> correlation_factor_;
  std::vector<Setter> setters_;
  std::vector<std::vector<double>> places_;
  std::vector<RobotPlace> robot_places_;
  Structure nominal_;
  /// A cut's radial depth and direction, and its mean cutting stiffness.
  struct Cut {
    cutting::MillingProcess process;  ///< the job's, with the cut's ae and direction
    stability::MeanCuttingStiffnessBasis basis;
  };
  /// learn.method: the zero-order limit, or a time-domain method's.
  job::StabilitySettings::Method method_ = job::StabilitySettings::Method::zoa;
  int steps_ = 40;  ///< stability.discretization (time-domain methods)
  std::optional<tool::Tool> tool_;
  std::vector<Cut> cuts_;
  std::vector<std::vector<double>> experiment_postures_;
  int teeth_ = 0;
  double search_depth_m_ = 0.0;
};

}  // namespace robomill::analysis

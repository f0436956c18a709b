#pragma once
// The structure a job describes, in the form the analyses take: the modal
// table, modes fitted to measured FRFs, or the measured FRFs themselves
// (`dynamics.use`, docs/job-reference.md).

#include <vector>

#include "robomill/dynamics/frf.hpp"
#include "robomill/dynamics/modal_fit.hpp"
#include "robomill/dynamics/modal_model.hpp"
#include "robomill/job/job.hpp"

namespace robomill::analysis {

/// Every FRF of the files in `dynamics.frf`, in SI units and tool-frame axes.
/// Throws InputError naming the entry (and the file's line) for unreadable
/// or malformed files, or a file whose directions are not x, y or z.
std::vector<dynamics::Frf> load_measured_frfs(const job::Job& job);

/// The modal fit of the job's measured FRFs: one fit per driving-point FRF
/// (response = reference direction), each direction with its own modes, as
/// hammer tests at a robot's tool tip give them. Cross FRFs are not fitted.
struct StructureFit {
  std::vector<dynamics::Frf> measured;   ///< the driving-point FRFs fitted, in order
  std::vector<dynamics::ModalFit> fits;  ///< one per measured FRF
  dynamics::ModalModel modes;            ///< every fitted mode along its direction
};

/// Fits `measured` (as load_measured_frfs returns) with the job's
/// `dynamics.fit` settings. Throws InputError naming `dynamics.frf` when no
/// driving-point FRF is given and `dynamics.fit` when the settings do not
/// suit the data; NumericalError when a band holds no stable pole.
StructureFit fit_structure(const job::Job& job, const std::vector<dynamics::Frf>& measured);

/// The modes the analyses use: the modal table (`dynamics.use: table`) or the
/// modes fitted to the measured FRFs (`fit`). For `frf` (measured FRFs used
/// directly) there are no modes: throws InputError naming `dynamics.use`.
dynamics::ModalModel structure_modes(const job::Job& job);

}  // namespace robomill::analysis

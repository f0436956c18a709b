#pragma once
// A job: one robot cell and one question (DESIGN.md §3), validated and in SI.
// The numerical core never sees the YAML; it sees these values.

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "robomill/atlas/atlas.hpp"
#include "robomill/cutting/cutting_law.hpp"
#include "robomill/cutting/process.hpp"
#include "robomill/dynamics/axial_shape.hpp"
#include "robomill/dynamics/frf.hpp"
#include "robomill/dynamics/modal_model.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/io/recording.hpp"
#include "robomill/job/units.hpp"
#include "robomill/monitoring/recording_analysis.hpp"
#include "robomill/planning/cutting_advice.hpp"
#include "robomill/planning/pose_optimization.hpp"
#include "robomill/robot/posture_interpolation.hpp"
#include "robomill/robot/robot_description.hpp"
#include "robomill/robot_path/feed_schedule.hpp"
#include "robomill/tool/tool.hpp"
#include "robomill/uncertainty/distribution.hpp"
#include "robomill/uncertainty/draws.hpp"

namespace robomill::job {

/// `forces:` section — how `robomill forces` samples the force history.
struct ForcesSettings {
  int revolutions = 1;
  int steps_per_tooth = 90;
  int axial_elements = 0;  ///< 0: chosen so that each element spans ≤ 1° of helix lag
};

/// One structural mode in a modal table (`dynamics.modes`, 000 Table 2, 003 Tab. 1).
struct ModeSpec {
  char direction = 'x';  ///< 'x', 'y' or 'z' (tool frame); 'v' for a general direction
  /// Unit vector of the mode's motion at the tip (tool frame): e_x, e_y, e_z,
  /// or any direction (`direction: [0.8, 0.6, 0]`), which couples x and y.
  Eigen::Vector3d direction_vector = Eigen::Vector3d::UnitX();
  double natural_frequency_hz = 0.0;
  double damping_ratio = 0.0;
  double stiffness_n_per_m = 0.0;  ///< modal stiffness at the tool tip; from m or the shape
  double mass_kg = 0.0;            ///< modal mass at the tool tip; from k or the shape
  /// Mass-normalized shape measured at points along the tool (`shape:`, 000
  /// Table 2 and Eq 35): distance from the tool tip (m) and value (1/√kg),
  /// sorted by distance; empty when the mode is given by k or m.
  dynamics::AxialShape shape;
};

/// One measured FRF file (`dynamics.frf`): UFF58 (ASCII or binary) or CSV.
struct FrfFileSpec {
  std::filesystem::path file;  ///< resolved against the job's folder
  enum class Format { uff58, csv } format = Format::uff58;
  /// Tool-frame axes; for UFF58 taken from the file unless given here.
  std::optional<int> response_axis, reference_axis;
  /// `units:` ("mm/N", "m/s/N", "m/s^2/N"): the kind and the SI factor of the
  /// file's values. Required for CSV; for UFF58 it overrides the file's units.
  std::optional<dynamics::FrfKind> kind;
  double scale_to_si = 1.0;
  std::string path;  ///< job path for messages, `dynamics.frf[0]`
  int line = 0;
};

/// `dynamics.fit`: how `robomill fit-modes` extracts modes from the FRFs.
struct FitSettings {
  struct Band {
    double low_hz = 0.0, high_hz = 0.0;
    int max_order = 0;  ///< 0: the fit's default
  };
  std::vector<Band> bands;  ///< empty: automatic band selection
  int max_order = 0;        ///< 0: the fit's default
};

/// `dynamics.postures`: modal tables measured at several postures of the
/// robot (hammer tests at the tool tip, 001 §3.1), interpolated in joint
/// space by inverse-distance weighting (001 Eq 16-18) at the posture the
/// analyses run at (`dynamics.at`, else `robot.posture`).
struct PostureLibrary {
  std::vector<Eigen::VectorXd> postures_rad;  ///< one per measured posture
  std::vector<std::vector<ModeSpec>> tables;  ///< the modes measured there
  robot::IdwOptions idw;                      ///< `dynamics.idw: {power, joint_weights}`
  Eigen::VectorXd query_rad;                  ///< where the table is interpolated
  std::string query_source;                   ///< "dynamics.at" or "robot.posture"
  Eigen::VectorXd weights;                    ///< α_i at the query (001 Eq 18)
  int exact_index = -1;                       ///< a measured posture hit exactly, or −1
};

/// `robot:` — the robot's description and what `robomill robot` computes.
struct RobotSettings {
  robot::RobotDescription description;
  std::filesystem::path urdf_file;  ///< where `urdf.file` pointed (for messages)
  /// `posture:` joint angles (rad), one per joint; empty when not given.
  std::vector<double> posture_rad;
  /// `frf:` tool-tip receptance grid at the posture.
  double frf_from_hz = 0.0, frf_to_hz = 0.0;  ///< 0: automatic
  int frf_points = 500;
  /// `map:` a grid of tool-tip positions in the cell frame.
  struct Map {
    Eigen::Vector3d from_m = Eigen::Vector3d::Zero(), to_m = Eigen::Vector3d::Zero();
    std::array<int, 3> counts{1, 1, 1};
    Eigen::Vector3d tool_axis = Eigen::Vector3d::UnitZ();  ///< tool z, tip → spindle
    Eigen::Vector3d feed = Eigen::Vector3d::UnitX();       ///< feed direction (⊥ tool axis)
    double redundancy_rad = 0.0;
  };
  std::optional<Map> map;
};

/// One cutting test with its observed outcome (`experiments:`).
struct Experiment {
  double spindle_rad_s = 0.0;
  double axial_depth_m = 0.0;
  bool chatter = false;
  /// `chatter_freq`: the chatter line heard (Hz); 0 when not given.
  double chatter_frequency_hz = 0.0;
  /// `power`: the spindle's cutting power during the test (W, above its
  /// idle power); 0 when not given.
  double power_w = 0.0;
  /// `posture`: the robot's joint angles (rad) during the test; empty:
  /// robot.posture (or `position`'s).
  std::vector<double> posture_rad;
  /// `position`: the tool tip in the workpiece frame (m) during the test,
  /// the tool along the workpiece's z; `robomill learn` finds the posture
  /// from workpiece.pose and robot_path.redundancy.
  std::optional<Eigen::Vector3d> position_m;
  /// `ae`, `direction`, `feed_per_tooth`: the test's cut where it differs
  /// from the job's process (nullopt: the process's).
  std::optional<double> radial_depth_m, feed_per_tooth_m;
  std::optional<cutting::MillingDirection> direction;
  /// `frf:` a hammer test (files as dynamics.frf) at the test's posture:
  /// no cut, so no spindle, depth or verdict.
  std::vector<FrfFileSpec> frf_files;
  bool hammer() const noexcept { return !frf_files.empty(); }
  /// Whether `chatter` was written; false when only a recording says.
  bool verdict_given = true;
  /// `recording:` the cut's recording (as `recordings[]`): `learn` takes the
  /// verdict, the chatter frequency and the measured spindle speed from
  /// `listen`'s analysis of it. Its spindle and depth default to the test's.
  std::optional<io::RecordingSpec> recording;
  int line = 0;  ///< the entry's line (for messages)
};

/// `stability:` section — how `robomill stability` computes the lobes.
struct StabilitySettings {
  enum class Method { zoa, sdm, fdm, fdm2 };
  enum class Mode { boundary, map };
  enum class Modes { coupled, envelope, both };  ///< all modes together, and/or 003's envelope
  Method method = Method::fdm;
  Mode mode = Mode::boundary;
  Modes modes = Modes::coupled;
  double speed_from_rad_s = 0.0, speed_to_rad_s = 0.0;  ///< `speeds: {from, to, count}` (rpm)
  int speed_count = 0;
  double depth_max_m = 0.0;       ///< `depth_max` (mm): upper end of the depth search / map
  int depth_count = 100;          ///< `depths`: map rows (map mode)
  double depth_tolerance = 1e-3;  ///< `depth_tolerance`: relative precision of each limit
  bool continuation = false;      ///< `continuation`: start from the extrapolated limit
  /// `deformation`: also the diagrams with 000's deformation-corrected
  /// engagement (and with process damping, when given): 000 Figures 12-13.
  bool deformation = false;
  int discretization = 40;  ///< `discretization`: steps per tooth period (SDM/FDM)
  /// `process_damping: {model: linear_equivalent|energy_balance, Ksp, wear_land, mu}`
  /// (000 Eq 18-19; 003 §3.1). Ksp in N/m^3, wear_land in um, mu dimensionless.
  enum class Damping { none, linear_equivalent, energy_balance };
  Damping process_damping = Damping::none;
  double indentation_n_per_m3 = 0.0;
  double wear_land_m = 0.0;
  double friction = 0.0;
};

/// `workpiece:` — the work table and the part's pose on it (004 §4.1, Eq 7).
struct WorkpieceSettings {
  planning::Workcell cell;
  std::optional<planning::WorkpiecePose> pose;  ///< `pose: [xp, yp, θp]`
};

/// `optimize:` — the workpiece pose search of `robomill optimize` (004 Eq 8-9).
struct OptimizeSettings {
  planning::PoseBounds bounds;
  planning::PoseOptimizationOptions options;
  planning::OffsetMeasure measure = planning::OffsetMeasure::peak;
  int harmonics = 60;                          ///< force harmonics kept
  int samples = 256;                           ///< force samples per period
  std::vector<planning::WorkpiecePose> poses;  ///< `poses:` evaluated and reported
  std::array<int, 2> landscape_counts{0, 0};   ///< `landscape.counts` [nx, ny]; 0: none
  std::vector<double> landscape_theta_rad;     ///< `landscape.theta`
  /// `check_time_domain`: integrate Eq 1 in time at the best pose's first
  /// point and report the difference to the harmonic steady state.
  bool check_time_domain = false;
};

/// `deflection:` — 000's force-induced deformation (§2, §4): the model of
/// `robomill deflection` and of `stability.deformation`.
struct DeflectionSettings {
  int elements = 10;                   ///< m axial elements, m + 1 nodes (000 §2)
  double equivalent_diameter_m = 0.0;  ///< bending section of the tool; 0: 0.8 × diameter
  bool chip_correction = true;         ///< 000 Eq 21/28's static-chip correction
  bool robot = true;                   ///< the robot's joint springs at robot.posture (Eq 3)
  /// `depths: {from, to, count}` of `robomill deflection`; 0: automatic
  /// (from ap_lim/8 to 1.5 ap_lim, Eq 22).
  double depth_from_m = 0.0, depth_to_m = 0.0;
  int depth_count = 12;
  int table_depths = 48;  ///< depths the stability engine interpolates the engagement over
};

/// `simulation:` — the time-domain simulation of `robomill simulate`
/// (002 §2.5-3.4; docs/simulation.md). SI units.
struct SimulationSettings {
  /// `model`: the structure moved by the cutting forces.
  ///  modes: the job's modal model (dynamics:, whatever its source);
  ///  rigid: 002 Case A; fixation: 002 Eq 32 (1dof, x), Eq 33 (2dof, x y),
  ///  3dof (x y z) with `fixation: {mass, stiffness, damping | damping_ratio}`;
  ///  reduced6d: the robot's reduced model Mr, Kr (002 Eq 23) at robot.posture.
  enum class Model { modes, rigid, fixation, reduced6d };
  Model model = Model::modes;
  std::string model_name = "modes";
  Eigen::MatrixXd mass_kg, damping_n_s_per_m, stiffness_n_per_m;  ///< fixation (n×n)
  double damping_ratio = 0.0;             ///< reduced6d: ζ of modes the robot leaves undamped
  double duration_s = 0.0;                ///< `duration`, or `revolutions` converted
  std::string duration_key = "duration";  ///< the key the user gave it by
  int steps_per_tooth = 40;
  /// false: `steps_per_tooth` not in the job — the command raises the
  /// default to what the structure and the engaged arc need.
  bool steps_per_tooth_given = false;
  int axial_elements = 0;  ///< 0: as `forces` (helix lag ≤ 0.5° per element)
  /// `workpiece.border` (or `workpiece_mesh.border`, DESIGN.md's name): gap
  /// between the cutter's leading edge and the part's straight border at
  /// t = 0 (0: touching, 002's t = 0); none: in the cut.
  std::optional<double> border_gap_m;
  std::string workpiece_key = "workpiece";  ///< the key the user gave it by
  double steady_window_s = 0.0;  ///< `steady_revolutions` (default: the last 20 % of the run)
  double start_angle_rad = 0.0;  ///< `start_angle`: tooth 1's angle at t = 0
  int record_every = 1;          ///< `record_every`: rows of timeseries.csv per step
  /// `process_damping: {Ksp, wear_land, mu}` (000 Eq 18-19).
  bool process_damping = false;
  double indentation_n_per_m3 = 0.0, wear_land_m = 0.0, friction = 0.0;
  /// Lines of the fields the command checks against the structure (0: absent).
  int line = 0, steps_line = 0, duration_line = 0, border_line = 0;
};

/// `advise:` — the cutting-parameter advice of `robomill advise` (issue 9
/// item 4): the spindle range, depth resolution, stability margin and offset
/// limit, the stability engine, and optionally the redundancy-angle study.
struct AdviseSettings {
  planning::AdviceLimits limits;  ///< speeds, refine, depth_step, margin, max_offset, measure
  planning::LimitSettings limit;  ///< method, discretization, depth_max, depth_tolerance
  int peaks = 5;                  ///< runner-ups reported
  /// `max_chatter_probability`: with an uncertainty: section, the robust
  /// advice keeps P(chatter) over the draws at most this (issue 33).
  double max_chatter_probability = 0.05;
  /// `along: path`: every point of the job's path at workpiece.pose is a
  /// station (the robot's modes there); `posture` (default): the job's
  /// structure (dynamics:) at robot.posture.
  bool along_path = false;
  double redundancy_angle_rad = 0.0;  ///< `redundancy_angle`: ψ used along the path
  /// `redundancy: {angles: {from, to, count}, at: range|spindle}`.
  struct Redundancy {
    std::vector<double> angles_rad;
    bool at_spindle = false;  ///< a_min at process.spindle instead of over the speeds
  };
  std::optional<Redundancy> redundancy;
};

/// `surface:` — the Z-map topography of `robomill surface` (001 §2.4;
/// docs/surface.md). SI units; the checks that need the tool and the grid
/// together (001 Eq 29-31, coverage, shank) are made by the command, which
/// names these fields with the lines kept here.
struct SurfaceSettings {
  double area_x_m = 0.0, area_y_m = 0.0;      ///< `area: [Lx, Ly]` (mm)
  int cells_x = 0, cells_y = 0;               ///< `grid: [nx, ny]` cells
  double origin_x_m = 0.0, origin_y_m = 0.0;  ///< `origin: [x0, y0]` (mm)
  double stepover_m = 0.0;                    ///< `stepover` (mm), default process.ae
  int passes = 0;                             ///< `passes`; 0: enough to cover the area
  std::optional<double> first_pass_y_m;       ///< `first_pass` (mm): y of pass 1
  bool zigzag = false;                        ///< `pattern: one_way | zigzag`
  double lead_rad = 0.0, tilt_rad = 0.0, redundancy_rad = 0.0;  ///< 001 Eq 5 (deg)
  bool vibration = false;                                       ///< `vibration`: 001 §2.2-2.3
  std::optional<double> warmup_s;                               ///< `warmup` (s) before the patch
  /// `entry` (mm): every pass enters the part this far before the patch
  /// (the vibration restarts with each pass); none: a steady cut.
  std::optional<double> entry_m;
  /// `start: rest`: every pass's vibration starts from rest with the cut
  /// fully engaged — 001 §2.2.2's dde23 solution from a zero history (the
  /// start-up transient imprints on the patch); false: `steady`.
  bool start_at_rest = false;
  int simulation_steps_per_tooth = 0;  ///< `steps_per_tooth`; 0: automatic
  int steps_per_revolution = 0;        ///< `steps_per_revolution`; 0: Eq 30
  double edge_spacing_m = 0.0;         ///< `edge_spacing` (mm); 0: Eq 31
  bool grid_rule = true;               ///< `grid_rule: true`: enforce Eq 29
  /// Lines for messages (0: absent).
  int line = 0, grid_line = 0, passes_line = 0, first_pass_line = 0, lead_line = 0, tilt_line = 0,
      steps_line = 0, spacing_line = 0, vibration_line = 0, area_line = 0;
};

/// `toolpath:` — the program the cell runs (`robomill toolpath`,
/// docs/toolpath.md). SI units; the program itself is read by the command.
struct ToolpathSettings {
  using Format = io::ProgramFormat;
  std::filesystem::path file;  ///< resolved against the job's folder
  std::string file_text;       ///< as written in the job (messages)
  Format format = Format::gcode;
  /// Program frame → workpiece frame: `origin` (mm) and `orientation` (deg,
  /// A B C about z, y', x'' as KUKA writes frames).
  Eigen::Isometry3d program_to_workpiece = Eigen::Isometry3d::Identity();
  /// `tools: {T1: {tool fields}, ...}`: cutters by tool number; empty: the
  /// job's `tool` serves every tool number.
  std::map<int, tool::ToolSpec> tools;
  double spacing_m = 0.0;                         ///< `spacing`; 0: a few feeds per tooth
  double rapid_speed_m_s = 0.5;                   ///< `rapid_speed` (30 m/min)
  double spindle_rad_s = 0.0;                     ///< `spindle`: when the program gives none
  int force_steps_per_tooth = 32;                 ///< `steps_per_tooth`
  std::size_t block_samples = 4096;               ///< `block_samples`
  std::size_t max_bytes = 64u << 20;              ///< `max_size`
  std::map<int, Eigen::Vector3d> work_offsets_m;  ///< G-code `work_offsets: {G54: [x, y, z]}`
  std::filesystem::path dat_file;                 ///< KRL `dat` (default: the .src's .dat)
  std::map<int, Eigen::Isometry3d> bases;         ///< KRL `bases: {1: [x, y, z, a, b, c]}`
  char tool_direction = 'x';                      ///< KRL `tool_direction`
  /// APT `units`: the length unit of a CL file without a UNITS record (NX
  /// writes none); unset: the first feed's unit, else mm.
  using Units = io::AptLengthUnit;
  Units units = Units::unset;
  int line = 0, file_line = 0, tools_line = 0;
};

/// `stock:` — the raw part the program cuts (workpiece frame).
struct StockSettings {
  Eigen::Vector3d min_m = Eigen::Vector3d::Zero(), max_m = Eigen::Vector3d::Zero();
  double resolution_m = 0.0;         ///< `resolution` (default: tool diameter / 20)
  std::filesystem::path height_map;  ///< `height_map`: stock.csv of an earlier run
  int line = 0, resolution_line = 0;
};

/// `robot_path:` — the robot along the program (`robomill toolpath` with a
/// `robot:` and `workpiece.pose`; docs/toolpath.md): the redundancy angle and
/// the shortcut's tolerance (robot_path/robot_along_path.hpp).
struct RobotPathJobSettings {
  double redundancy_rad = 0.0;  ///< `redundancy` (deg): ψ about the tool axis
  double tolerance = 0.02;      ///< `tolerance`: interpolated stable depths within this
  int max_span = 64;            ///< `max_span`: samples between two exact limits at most
  int check_every = 25;         ///< `check_every`: interpolated samples also computed exactly
  double risk_margin = 1.0;     ///< `risk_margin`: at risk when a_lim < risk_margin × ap
  int worst_lines = 10;         ///< `worst_lines`
  /// `max_chatter_probability`: with an uncertainty: section, the lines
  /// whose P(chatter) over the draws exceeds it are reported (issue 33).
  double max_chatter_probability = 0.05;
  /// `redundancy_search: {from, to, count}` (deg): the angles --optimize
  /// tries for the whole program; empty: ψ stays.
  std::vector<double> redundancy_search_rad;
  /// `redundancy_search.per_line`: one angle per program line (the schedule
  /// ψ(s), turning between lines within `joint_speed_max`) instead of one
  /// for the program.
  bool redundancy_per_line = false;
  /// `redundancy_search.joint_speed_max` (deg/s): the schedule's turns; 0:
  /// feed_limits.joint_speed_max, else 10 deg/s.
  double redundancy_joint_speed_rad_s = 0.0;
  /// `deflection: static|contact`: the static tip deflection at every
  /// sample, or 000's contact boundary where a sample finishes a
  /// down-milling wall (the model of `robomill deflection`).
  bool contact_deflection = false;
  /// `feed_limits:` — the caps `--optimize` keeps every line's feed under
  /// (robot_path/feed_schedule.hpp: the schedule's own struct, SI, its
  /// `job_line` the section's line; unset caps 0).
  using FeedLimits = robot_path::FeedLimits;
  std::optional<FeedLimits> feed_limits;
  /// `offset:` — 004's steady-state offset at every sample
  /// (RobotPathSettings::offset); unset keys take the job's `optimize:`
  /// values, else peak, 60 harmonics, 256 samples.
  struct Offset {
    std::optional<planning::OffsetMeasure> measure;  ///< `measure`
    std::optional<int> harmonics, samples;           ///< `harmonics`, `samples`
    int line = 0;
  };
  std::optional<Offset> offset;
  /// `compensation:` — `--optimize` moves the program's end points against
  /// the predicted form error (robot_path/deflection_compensation.hpp).
  struct Compensation {
    bool floor = false;          ///< `floor`: also along the axis by the floor error
    double min_offset_m = 1e-6;  ///< `min_offset` (um): smaller corrections are not written
    double tolerance_m = 2e-6;   ///< `tolerance` (um): the written polyline within this
    int line = 0;
  };
  std::optional<Compensation> compensation;
  int line = 0;
};

/// `listen:` — how `robomill listen` judges recordings (docs/monitoring.md).
/// The recordings themselves are `recording:` / `recordings:`.
struct ListenSettings {
  std::optional<int> teeth;  ///< `teeth`: else tool.teeth (1 for a single insert)
  /// The detector's settings: spindle_search_fraction (`spindle_search`),
  /// chatter_line_threshold (`threshold`), detect_mains (`mains`: auto or
  /// off), detect_steady_lines (`steady_lines`), band_low_hz and band_high_hz
  /// (`band`: [low, high]; 0: automatic) and segment_s (`segment`; 0:
  /// automatic). The rest (the commanded speed, the teeth, the recording's
  /// ignore list) is each recording's, set by `robomill listen`.
  monitoring::ListenOptions detector;
  /// `spindle_range: [min, max]` for the advice; else advise.speeds, else
  /// stability.speeds, else half to one and a half times the spindle speed.
  std::optional<std::pair<double, double>> spindle_range_rad_s;
  int line = 0;
};

struct OutputSettings {
  std::string dir;  ///< empty: the command's default (out/<command>)
  bool csv = true, json = true, html = true;
};

/// `uncertainty:` — the job's uncertain inputs (issue 33; docs/uncertainty.md,
/// "From a job"): variables that set job fields, each drawn from a
/// distribution (uncertainty/distribution.hpp) or read from a posterior file,
/// and how many draws are made, from which seed, by which points.
struct UncertaintySettings {
  /// One job field a variable sets, resolved against the job at parse time.
  struct Target {
    std::string path;         ///< in the reader's bracket form: "dynamics.modes[0].k"
    double nominal_si = 0.0;  ///< the job's own value there, in SI (si_unit(dimension))
    Dimension dimension;      ///< the field's dimension (the job schema's unit)
    int line = 0;             ///< the line the path is written on (0: from --set)
  };
  /// What the drawn number is.
  enum class Mode {
    value,  ///< the field's value itself (SI)
    scale   ///< a dimensionless factor (median 1) multiplying every target's nominal value
  };
  /// One uncertain input (`variables[]`).
  struct Variable {
    std::string name;             ///< `name`: unique, [A-Za-z_][A-Za-z0-9_]*
    std::vector<Target> targets;  ///< `path`: one field or several, each set by this variable
    Mode mode = Mode::value;      ///< `mode`
    /// `distribution` and its parameters, resolved: in SI for mode value
    /// (the job's value the default mean or median), factors for mode scale
    /// (default mean or median 1). nullopt only with a posterior file.
    std::optional<uncertainty::Distribution::Parameters> distribution;
    int line = 0;  ///< the line of the variable's entry
  };
  std::vector<Variable> variables;  ///< `variables`, in the job's order (≥ 1)
  int samples = 1000;               ///< `samples`: draws, ≥ 1
  /// Whether `samples` was written: with a posterior, that many of its rows
  /// (evenly spaced) are used; all of them otherwise.
  bool samples_given = false;
  std::uint64_t seed = 1;  ///< `seed`
  /// `sampling`: randomly shifted Sobol points (default) or pseudo-random ones.
  uncertainty::DrawSettings::Sampling sampling = uncertainty::DrawSettings::Sampling::sobol;
  /// `correlation` (by names) as a variables × variables matrix in the
  /// variables' order, checked to be a correlation matrix
  /// (uncertainty::correlation_factor); nullopt: independent variables.
  std::optional<Eigen::MatrixXd> correlation;
  /// `posterior`: a CSV of draws (one column per variable, named by it)
  /// used instead of drawing; resolved against the job's folder; empty: none.
  std::filesystem::path posterior;
  int line = 0;              ///< the section's line
  int correlation_line = 0;  ///< `correlation`'s line
  int posterior_line = 0;    ///< `posterior`'s line
};

/// `learn:` — how `robomill learn` updates the uncertain inputs from the
/// experiments and chooses the next test (issue 35; docs/learning.md).
struct LearnSettings {
  /// `strategy`: the next test by expected information, by removal rate, or
  /// information until the boundary's spread stops shrinking (switching).
  enum class Strategy { information, productivity, switching };
  Strategy strategy = Strategy::switching;
  double max_risk = 0.5;              ///< `max_risk`: P(chatter) allowed for the next test
  int samples = 4000;                 ///< `samples`: posterior samples (SMC particles)
  std::uint64_t seed = 1;             ///< `seed` (default: uncertainty.seed)
  double verdict_sd_m = 0.1e-3;       ///< `verdict_sd`: σ_abs of the probit (m)
  double verdict_relative_sd = 0.05;  ///< `verdict_relative_sd`: σ_rel of the probit
  double mislabel = 0.01;             ///< `mislabel`: ε, a verdict's chance of being wrong
  double chatter_freq_sd_hz = 20.0;   ///< `chatter_freq_sd`: σ_f (Hz)
  double power_sd_w = 20.0;           ///< `power_sd`: σ_P of a measured power (W)
  /// `method`: the limit the verdicts' probit is centred on: zero-order
  /// (zoa, the anchor's) or a time-domain method (sdm, fdm, fdm2, with
  /// stability.discretization steps; some 100 times slower).
  StabilitySettings::Method method = StabilitySettings::Method::zoa;
  /// `frf_fn_sd`, `frf_k_sd`, `frf_zeta_sd`: relative (log-normal) spreads
  /// of a hammer test's fitted fn, k and ζ around the nearest predicted mode.
  double frf_fn_sd = 0.02, frf_k_sd = 0.20, frf_zeta_sd = 0.30;
  double spread_shrink = 0.05;  ///< `spread_shrink`: switching's least relative shrink per test
  /// `places[].posture`: further robot postures (rad) where the lobes are
  /// predicted and the next test may be proposed.
  std::vector<std::vector<double>> places_rad;
  int line = 0;  ///< the section's line (0: not written, defaults)
};

/// `--set key.path=value`: replaces (or adds) one field before validation.
/// The value is read as YAML, so lists and quoted quantities work:
/// `--set process.ae="2 mm"`, `--set forces.revolutions=3`.
struct Override {
  std::string path;
  std::string value;
};

struct Job {
  std::filesystem::path source;  ///< the job file ("" for text jobs)
  std::string name;              ///< `name:` (optional), for reports
  std::optional<tool::ToolSpec> tool;
  std::optional<cutting::CuttingLaw> cutting;
  std::optional<cutting::MillingProcess> process;
  ForcesSettings forces;
  std::optional<StabilitySettings> stability;
  std::vector<ModeSpec> modes;
  std::vector<FrfFileSpec> frf_files;  ///< `dynamics.frf`
  FitSettings fit;                     ///< `dynamics.fit`
  /// `dynamics.use`: what the analyses take as the structure — the modal
  /// table, modes fitted to the FRF files, or (zero-order stability only)
  /// the measured FRFs themselves.
  /// `robot`: the robot model's tool-tip modes at robot.posture
  /// (`dynamics.from_robot: true`).
  /// `postures`: the modal table interpolated over `dynamics.postures`
  /// (001 Eq 16-18), stored in `modes` at parse time.
  enum class DynamicsSource {
    table,
    fit,
    frf,
    robot,
    postures
  } dynamics_source = DynamicsSource::table;
  std::optional<PostureLibrary> posture_library;  ///< `dynamics.postures`
  std::vector<Experiment> experiments;
  std::optional<RobotSettings> robot;              ///< `robot:`
  std::optional<WorkpieceSettings> workpiece;      ///< `workpiece:`
  std::vector<planning::PathPoint> path;           ///< `path:` (workpiece frame)
  std::optional<DeflectionSettings> deflection;    ///< `deflection:` (000 §2, §4)
  std::optional<OptimizeSettings> optimize;        ///< `optimize:`
  std::optional<AdviseSettings> advise;            ///< `advise:`
  std::optional<SimulationSettings> simulation;    ///< `simulation:`
  std::optional<atlas::AtlasSpec> atlas;           ///< `atlas:` (docs/atlas.md)
  std::optional<SurfaceSettings> surface;          ///< `surface:` (docs/surface.md)
  std::optional<ToolpathSettings> toolpath;        ///< `toolpath:` (docs/toolpath.md)
  std::optional<StockSettings> stock;              ///< `stock:` (docs/toolpath.md)
  std::optional<RobotPathJobSettings> robot_path;  ///< `robot_path:` (docs/toolpath.md)
  /// `recording:` (one cut) or `recordings:` (several, each with its own
  /// spindle and depth) for `robomill listen` (docs/monitoring.md): at most
  /// one of the two; `recording` is held as the list's only entry.
  std::vector<io::RecordingSpec> recordings;
  bool recordings_listed = false;                  ///< written as `recordings:`
  std::optional<ListenSettings> listen;            ///< `listen:`
  std::optional<UncertaintySettings> uncertainty;  ///< `uncertainty:` (docs/uncertainty.md)
  std::optional<LearnSettings> learn;              ///< `learn:` (docs/learning.md)
  OutputSettings output;
  /// The YAML text the job was read from and the `--set` overrides it was
  /// read with (set by parse_job and load_job): with more overrides they
  /// rebuild the job (analysis/job_draws.hpp). nullptr for a Job built in code.
  std::shared_ptr<const std::string> yaml_text;
  std::vector<Override> overrides;

  /// Resolves a path written in the job relative to the job file's folder.
  std::filesystem::path resolve(const std::filesystem::path& relative) const;
};

/// Parses `key.path=value`; throws InputError naming `--set` when malformed.
Override parse_override(std::string_view assignment);

/// Reads, overrides and validates a job file. Every problem becomes an
/// InputError naming the field path and its line (YAML syntax errors, unknown
/// keys, wrong types, unknown or mismatched units, out-of-range or non-finite
/// values, cross-field inconsistencies such as ae > tool diameter).
Job load_job(const std::filesystem::path& file, const std::vector<Override>& overrides = {});

/// The same from text; `source_name` is used in messages and to resolve paths.
/// Texts over 1 MiB, nested deeper than 64 levels, or holding more than one
/// YAML document are rejected before or instead of being handed to yaml-cpp
/// (see fuzz/README.md for why).
Job parse_job(std::string_view yaml_text, const std::filesystem::path& source_name,
              const std::vector<Override>& overrides = {});

/// The job's `dynamics.modes` as a modal model (each mode along its axis with
/// its modal stiffness). Throws InputError naming `dynamics.modes` when empty.
dynamics::ModalModel modal_model(const Job& job);

/// "table", "fit", "frf", "robot" or "postures" (summary.json's `dynamics`).
const char* dynamics_source_name(Job::DynamicsSource source);

/// Sections a command needs; throws InputError naming the first missing one.
enum class Section { tool, cutting, process, modes, stability, robot };
void require(const Job& job, std::initializer_list<Section> sections);

}  // namespace robomill::job

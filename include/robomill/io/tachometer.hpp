#pragma once
// The spindle speed from a tachometer or once-per-revolution channel of a
// recording (issue 34, `recording.tachometer`): a pulse train beside the
// signal (a WAV's second channel, a MAT or CSV column). Counting its pulses
// gives the speed the spindle really ran at, which the detector then uses
// instead of searching the spectrum for the comb (docs/monitoring.md).

#include <cstddef>

#include "robomill/io/recording.hpp"

namespace robomill::io {

struct TachometerReading {
  double spindle_hz = 0.0;     ///< mean over the channel: (pulses − 1) / span / pulses per rev
  std::size_t pulses = 0;      ///< rising edges counted
  double period_spread = 0.0;  ///< coefficient of variation of the pulse periods
};

/// Reads spec.tachometer (the channel of a sound file, the column of a MAT
/// or CSV file) over the same stretch as the signal (start, duration) in two
/// streaming passes: its range, then its rising edges through the middle of
/// the range (hysteresis at 30 % and 70 %, each edge's time interpolated
/// between samples). Throws InputError (field "<path>.tachometer") for a
/// channel that is flat, holds fewer than 3 pulses, or whose pulse periods
/// vary by more than a quarter (pulses missed or doubled); the reader's own
/// errors for a channel or column that is not there.
TachometerReading read_tachometer(const RecordingSpec& spec);

}  // namespace robomill::io

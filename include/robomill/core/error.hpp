#pragma once
// Errors robomill raises. Two families matter to callers:
//  * InputError  — the user's job, file or arguments are wrong (exit code 2).
//  * everything else derived from Error — a failure while computing (exit code 1).
// Numerical code throws std::invalid_argument for violated preconditions on
// model descriptions; the job parser turns user input into validated models so
// such an exception reaching the top indicates a bug or an unchecked API use.

#include <stdexcept>
#include <string>

namespace robomill {

/// Base class of every error robomill throws on purpose.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Invalid user input: a job field, a data file, a command-line argument.
/// `field` is the dotted path (`tool.teeth`), `line` the 1-based line in the
/// source file (0 when unknown, e.g. a `--set` override).
class InputError : public Error {
 public:
  InputError(std::string field, int line, const std::string& message)
      : Error(format(field, line, message)), field_(std::move(field)), line_(line) {}

  const std::string& field() const noexcept { return field_; }
  int line() const noexcept { return line_; }

 private:
  static std::string format(const std::string& field, int line, const std::string& message) {
    std::string text = field;
    if (line > 0)
      text += " (line " + std::to_string(line) + ")";
    if (!text.empty())
      text += ": ";
    return text + message;
  }

  std::string field_;
  int line_ = 0;
};

/// A computation could not produce a trustworthy result (did not converge,
/// produced a non-finite value, ...).
class NumericalError : public Error {
 public:
  using Error::Error;
};

}  // namespace robomill

// Field checks shared by every option struct's validate(): each throws std::invalid_argument
// "<name>: must be ..., got <value>", so a bad setting is named where it is read.
#pragma once

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace bayesgrasp {

inline std::string number_str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

[[noreturn]] inline void bad_field(const std::string& name, const std::string& rule, const std::string& got) {
  throw std::invalid_argument(name + ": must be " + rule + ", got " + got);
}

/// Not NaN (an infinity may mean "off", as in a target of -inf).
inline void require_not_nan(double v, const std::string& name) {
  if (std::isnan(v)) bad_field(name, "a number", "nan");
}

inline void require_finite(double v, const std::string& name) {
  if (!std::isfinite(v)) bad_field(name, "finite", number_str(v));
}

inline void require_positive(double v, const std::string& name) {
  if (!(v > 0) || !std::isfinite(v)) bad_field(name, "positive and finite", number_str(v));
}

inline void require_non_negative(double v, const std::string& name) {
  if (!(v >= 0) || !std::isfinite(v)) bad_field(name, "finite and >= 0", number_str(v));
}

/// lo <= v <= hi.
inline void require_in(double v, double lo, double hi, const std::string& name) {
  if (!(v >= lo && v <= hi)) bad_field(name, "in [" + number_str(lo) + ", " + number_str(hi) + "]", number_str(v));
}

/// lo < v < hi.
inline void require_open(double v, double lo, double hi, const std::string& name) {
  if (!(v > lo && v < hi)) bad_field(name, "in (" + number_str(lo) + ", " + number_str(hi) + ")", number_str(v));
}

inline void require_at_least(long long v, long long lo, const std::string& name) {
  if (v < lo) bad_field(name, ">= " + std::to_string(lo), std::to_string(v));
}

}  // namespace bayesgrasp

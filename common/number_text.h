#pragma once
// A number as a user typed it, for messages that quote a value back: "5", "0.5", "1e+10", "nan" (std::to_string
// would write 5.000000).

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

namespace fishtank {

inline std::string number_text(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

// The shortest decimal that reads back as this float, for JSON: a flag's 0.6 prints as 0.6, not as
// 0.6000000238418579 (the float widened to a double).
inline double shortest_decimal(float value) {
  for (int digits = 6; digits <= 9; ++digits) {  // 9 always reads back
    char text[32];
    std::snprintf(text, sizeof text, "%.*g", digits, double(value));
    const double read = std::strtod(text, nullptr);
    if (static_cast<float>(read) == value) return read;
  }
  return value;
}

}  // namespace fishtank

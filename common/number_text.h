#pragma once
// A number as a user typed it, for messages that quote a value back: "5", "0.5", "1e+10", "nan" (std::to_string
// would write 5.000000).

#include <sstream>
#include <string>

namespace fishtank {

inline std::string number_text(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

}  // namespace fishtank

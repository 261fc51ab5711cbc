#pragma once
// Text from the other end of a connection as it may be shown or logged: control and non-ASCII bytes as \xNN,
// so that a peer cannot forge a line, move a terminal's cursor or hand a JSON writer invalid UTF-8; a backslash
// is escaped too, so that an escape cannot be faked. Cut to max_bytes of the original, then "...".

#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

namespace fishtank {

inline std::string printable_text(std::string_view raw, std::size_t max_bytes) {
  std::string text;
  for (std::size_t i = 0; i < raw.size() && i < max_bytes; ++i) {
    const auto c = static_cast<unsigned char>(raw[i]);
    if (c >= 0x20 && c < 0x7f && c != '\\') {
      text += static_cast<char>(c);
    } else {
      char escaped[5];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
      text += escaped;
    }
  }
  if (raw.size() > max_bytes) text += "...";
  return text;
}

// A server's words (an Error's message, a scene's name) as a client shows them: a foreign server's escape codes
// or invalid UTF-8 cannot forge a line, move the cursor or break the client's JSON writer.
inline std::string server_text(std::string_view raw) { return printable_text(raw, 512); }

}  // namespace fishtank

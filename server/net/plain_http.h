#pragma once
// A short plain-text HTTP/1.1 answer that closes the connection: what a browser
// gets where the server will not serve it (a full server, the TCP port).

#include <string>

namespace fishtank::net {

// status: the status line's code and reason, e.g. "503 Service Unavailable"; body: one or more lines.
inline std::string plain_http_response(const std::string& status, const std::string& body) {
  return "HTTP/1.1 " + status + "\r\nContent-Type: text/plain; charset=utf-8\r\nConnection: close\r\nContent-Length: " +
         std::to_string(body.size()) + "\r\n\r\n" + body;
}

}  // namespace fishtank::net

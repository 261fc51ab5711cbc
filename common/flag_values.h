#pragma once
// Boost.Program_options takes the token after a flag as its value even when that token is another flag, so
// "--record --bench" would record into a file named "--bench" and run the daemon. Every program parses through
// parse_flags, which refuses a value that starts with "--" (one dash stays a value: "--move -2,0,0").

#include <boost/program_options.hpp>
#include <string>

namespace fishtank {

// Parses argv against flags like po::parse_command_line; throws po::error naming the flag whose value is a flag.
inline boost::program_options::parsed_options parse_flags(int argc, const char* const argv[],
                                                          const boost::program_options::options_description& flags) {
  namespace po = boost::program_options;
  po::parsed_options parsed = po::parse_command_line(argc, argv, flags);
  for (const po::option& option : parsed.options)
    for (const std::string& value : option.value)
      if (value.rfind("--", 0) == 0)
        throw po::error("--" + option.string_key + " wants a value, got the flag '" + value + "'");
  return parsed;
}

}  // namespace fishtank

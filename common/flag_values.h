#pragma once
// Boost.Program_options takes the token after a flag as its value even when that token is another flag, so
// "--record --bench" would record into a file named "--bench" and run the daemon. Every program parses through
// parse_flags, which refuses a value that starts with "--" (one dash stays a value: "--move -2,0,0"), and says
// what a refused value should have been with flag_error_text.

#include <boost/program_options.hpp>
#include <string>

namespace fishtank {

// Parses argv against flags like po::parse_command_line; throws po::error naming the flag whose value is a flag,
// or a word that belongs to no flag (Boost drops those: "fishtank-client 10.0.0.5:7878" connected to the default).
inline boost::program_options::parsed_options parse_flags(int argc, const char* const argv[],
                                                          const boost::program_options::options_description& flags) {
  namespace po = boost::program_options;
  po::parsed_options parsed = po::parse_command_line(argc, argv, flags);
  for (const po::option& option : parsed.options) {
    if (option.position_key >= 0) {
      const std::string& word = option.value.front();
      const bool address = word.find(':') != std::string::npos && flags.find_nothrow("connect", false);
      throw po::error("unexpected '" + word + "': every setting is a flag and its value" +
                      (address ? " (did you mean --connect " + word + "?)" : ""));
    }
    for (const std::string& value : option.value)
      if (value.rfind("--", 0) == 0)
        throw po::error("--" + option.string_key + " wants a value, got the flag '" + value + "'");
  }
  return parsed;
}

namespace detail {
template <class... T>
bool holds_one_of(const boost::program_options::value_semantic* semantic) {
  return ((dynamic_cast<const boost::program_options::typed_value<T>*>(semantic) != nullptr) || ...);
}
}  // namespace detail

// A refused flag's words: Boost's, and where a value is not a number, which kind the flag takes ("the argument
// ('nan') for option '--balls' is invalid: it takes a whole number").
inline std::string flag_error_text(const boost::program_options::error& e,
                                   const boost::program_options::options_description& flags) {
  namespace po = boost::program_options;
  const auto* invalid = dynamic_cast<const po::invalid_option_value*>(&e);
  const std::string name = invalid ? invalid->get_option_name() : "";
  const po::option_description* option = name.rfind("--", 0) == 0 ? flags.find_nothrow(name.substr(2), false) : nullptr;
  if (!option) return e.what();
  const po::value_semantic* semantic = option->semantic().get();
  const std::string text = e.what();
  if (detail::holds_one_of<int, unsigned, long, unsigned long, long long, unsigned long long>(semantic)) {
    // Boost quotes the value as ('...'); one of digits alone is a whole number too large to hold.
    const std::size_t from = text.find("('") + 2, to = text.find("')");
    const bool digits =
        from >= 2 && to != std::string::npos && to > from && text.find_first_not_of("+-0123456789", from) >= to;
    return text + (digits ? ": that number is far too large" : ": it takes a whole number");
  }
  if (detail::holds_one_of<float, double>(semantic)) return text + ": it takes a number";
  return text;
}

}  // namespace fishtank

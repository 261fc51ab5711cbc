#pragma once
// Files written when a run ends (the server's final state, the accuracy tool's CSVs, a viewer's --screenshot),
// which may be an hour after it starts: their paths are checked first, so that a run cannot end in "cannot
// write" with its result lost.

#include <string>

namespace fishtank {

// "" where a file can be written at path (its folder exists and is writable,
// and so is the file if there is one), otherwise why not.
std::string check_writable_file(const std::string& path);

// Creates the folder dir if missing; "" where files can be written in it, otherwise why not.
std::string prepare_writable_folder(const std::string& dir);

}  // namespace fishtank

// One line of a CSV file split into its fields, as RFC 4180 quotes them: the readers of
// plinth-eval's runs files and of plinth-sweep's maps (which a spreadsheet may have saved).
#pragma once

#include <string>
#include <vector>

namespace plinth::host {

// The fields of `line` into `fields`: a field in double quotes may hold commas ("" is a
// quote); false on an unterminated quote (the fields then hold what was read).
bool split_csv(const std::string& line, std::vector<std::string>& fields);

}  // namespace plinth::host

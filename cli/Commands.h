#pragma once
#include <string>
#include <vector>

namespace parcelscope::cli {

/// Runs the subcommand named by args[0]; returns the exit code. Throws Error.
int dispatch(const std::vector<std::string>& args);

int metricsCommand(const std::vector<std::string>& args);
int statsCommand(const std::vector<std::string>& args);
int blocksCommand(const std::vector<std::string>& args);
int generateCommand(const std::vector<std::string>& args);
int compareCommand(const std::vector<std::string>& args);
int inspectCommand(const std::vector<std::string>& args);
int calibrateCommand(const std::vector<std::string>& args);
int editCommand(const std::vector<std::string>& args);
int mergeCommand(const std::vector<std::string>& args);

}  // namespace parcelscope::cli

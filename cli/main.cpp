// parcelscope: the batch command line. Each subcommand is a thin shell around a
// library function; errors map to exit codes 1 (failure), 2 (usage) and 130
// (stopped by Ctrl-C; nothing written).
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "Commands.h"
#include "Mpi.h"
#include "TermProgress.h"
#include "parcelscope/core/Error.h"

int main(int argc, char** argv) {
  const parcelscope::cli::MpiSession mpi(argc, argv);
  std::vector<std::string> args(argv + 1, argv + argc);
  const std::string command = args.empty() ? "" : args.front();
  parcelscope::cli::installInterruptHandler();
  // Under MPI, a rank that fails while others wait for it in a collective
  // would leave them waiting: it stops them all.
  auto stopRanks = [&](const char* what) {
    if (parcelscope::cli::mpiSize() <= 1) return;
    parcelscope::cli::abortRanks("parcelscope" + (command.empty() ? "" : " " + command) + " (rank " +
                                 std::to_string(parcelscope::cli::mpiRank()) + " of " +
                                 std::to_string(parcelscope::cli::mpiSize()) + "): " + what +
                                 "; every rank stopped, nothing was written");
  };
  try {
    return parcelscope::cli::dispatch(args);
  } catch (const parcelscope::Error& e) {
    stopRanks(e.what());
    const bool cancelled = e.kind() == parcelscope::Error::Kind::Cancelled;
    std::fprintf(stderr, "parcelscope%s: %s%s\n", command.empty() ? "" : (" " + command).c_str(), e.what(),
                 cancelled ? "; nothing was written" : "");
    if (cancelled) return 130;
    if (e.kind() == parcelscope::Error::Kind::Usage) {
      std::fprintf(stderr, "run 'parcelscope %s --help' for usage\n", command.c_str());
      return 2;
    }
    return 1;
  } catch (const std::exception& e) {
    stopRanks(e.what());
    std::fprintf(stderr, "parcelscope%s: internal error: %s\n", command.empty() ? "" : (" " + command).c_str(),
                 e.what());
    return 1;
  }
}

#pragma once
// Progress of a run on the console: on a terminal, one line updated in place a few times a second; otherwise
// (a log file, a pipe) a plain line at every tenth of the simulated time.
#include <cstdio>

#include "core/scene/runner.hpp"

namespace sph::app {

class ProgressPrinter {
 public:
  ProgressPrinter(std::FILE* out, bool quiet);
  void operator()(const scene::Progress& p);
  /// Ends the in-place line (before the summary).
  void done();

 private:
  std::FILE* out_;
  bool quiet_;
  bool terminal_;
  bool dirty_ = false;
  double last_wall_ = -1.0;
  int last_tenth_ = 0;
};

}  // namespace sph::app

#pragma once
// The CSV time series of a run: a header line of column names, then one line per output time, each
// written with one call and flushed, so a killed run leaves every finished line on disk.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace sph::io {

class TimeSeriesWriter {
 public:
  /// Creates the file with its header, or (append) continues an existing one.
  TimeSeriesWriter(const std::filesystem::path& file, const std::vector<std::string>& columns, bool append);
  TimeSeriesWriter(const TimeSeriesWriter&) = delete;
  TimeSeriesWriter& operator=(const TimeSeriesWriter&) = delete;
  ~TimeSeriesWriter();

  std::size_t columns() const { return columns_; }
  /// One row (values printed with 17 significant digits, integers exactly).
  void write(const std::vector<double>& values);

 private:
  std::FILE* file_ = nullptr;
  std::size_t columns_ = 0;
};

/// Keeps the header and the rows whose "step" column is at most max_step (resuming from a checkpoint),
/// rewriting the file atomically.
void truncate_time_series(const std::filesystem::path& file, std::uint64_t max_step);

}  // namespace sph::io

#include "core/io/time_series.hpp"

#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "core/io/atomic_file.hpp"

namespace sph::io {

TimeSeriesWriter::TimeSeriesWriter(const std::filesystem::path& file, const std::vector<std::string>& columns, bool append)
    : columns_(columns.size()) {
  file_ = std::fopen(file.c_str(), append ? "ab" : "wb");
  if (!file_) throw std::runtime_error("cannot write " + file.string());
  if (!append) {
    std::string header;
    for (const auto& c : columns) header += (header.empty() ? "" : ",") + c;
    header += '\n';
    std::fputs(header.c_str(), file_);
    std::fflush(file_);
  }
}

TimeSeriesWriter::~TimeSeriesWriter() {
  if (file_) std::fclose(file_);
}

void TimeSeriesWriter::write(const std::vector<double>& values) {
  std::string line;
  char buf[40];
  for (std::size_t k = 0; k < values.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%.17g", values[k]);
    if (k) line += ',';
    line += buf;
  }
  line += '\n';
  if (std::fwrite(line.data(), 1, line.size(), file_) != line.size() || std::fflush(file_) != 0) {
    throw std::runtime_error("cannot append to the time series");
  }
}

void truncate_time_series(const std::filesystem::path& file, std::uint64_t max_step) {
  std::istringstream in(read_file(file));
  std::string header, line, kept;
  if (!std::getline(in, header)) return;
  std::size_t step_column = 0;
  {
    std::istringstream h(header);
    std::string name;
    for (std::size_t k = 0; std::getline(h, name, ','); ++k) {
      if (name == "step") step_column = k;
    }
  }
  kept = header + '\n';
  while (std::getline(in, line)) {
    std::istringstream l(line);
    std::string cell;
    for (std::size_t k = 0; k <= step_column && std::getline(l, cell, ','); ++k) {
    }
    char* end = nullptr;
    const double step = std::strtod(cell.c_str(), &end);
    if (end == cell.c_str() || step > static_cast<double>(max_step)) break;
    kept += line + '\n';
  }
  write_file_atomic(file, kept);
}

}  // namespace sph::io

#include "core/io/atomic_file.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

namespace sph::io {

std::filesystem::path temporary_path(const std::filesystem::path& file) {
  std::filesystem::path tmp = file;
  tmp += ".tmp";
  return tmp;
}

void commit_file(const std::filesystem::path& file) {
  std::error_code ec;
  std::filesystem::rename(temporary_path(file), file, ec);
  if (ec) throw std::runtime_error("cannot rename " + temporary_path(file).string() + " to " + file.string() + ": " + ec.message());
}

void write_file_atomic(const std::filesystem::path& file, const std::string& content) {
  const std::filesystem::path tmp = temporary_path(file);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
    out << content;
    out.flush();
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  commit_file(file);
}

std::string read_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace sph::io

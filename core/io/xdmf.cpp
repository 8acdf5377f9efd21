#include "core/io/xdmf.hpp"

#include <cstdio>
#include <sstream>

#include "core/io/atomic_file.hpp"

namespace sph::io {

namespace {

std::string exact(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

void data_item(std::ostringstream& out, const XdmfEntry& e, const FieldLayout& f, const char* indent) {
  out << indent << "<DataItem Dimensions=\"" << e.frame.particles;
  if (f.components > 1) out << ' ' << f.components;
  out << "\" NumberType=\"" << f.number_type << "\" Precision=\"" << f.precision << "\" Format=\"HDF\">" << e.file
      << ":/" << e.frame.group << '/' << f.name << "</DataItem>\n";
}

}  // namespace

std::string xdmf_document(const std::vector<XdmfEntry>& frames) {
  std::ostringstream out;
  out << "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"2.0\">\n  <Domain>\n"
      << "    <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const XdmfEntry& e : frames) {
    out << "      <Grid Name=\"" << e.frame.group << "\" GridType=\"Uniform\">\n"
        << "        <Time Value=\"" << exact(e.frame.time) << "\"/>\n"
        << "        <Topology TopologyType=\"Polyvertex\" Dimensions=\"" << e.frame.particles << "\"/>\n";
    for (const FieldLayout& f : e.frame.fields) {
      if (f.name != "position") continue;
      out << "        <Geometry GeometryType=\"" << (f.components == 3 ? "XYZ" : "XY") << "\">\n";
      data_item(out, e, f, "          ");
      out << "        </Geometry>\n";
    }
    for (const FieldLayout& f : e.frame.fields) {
      if (f.name == "position") continue;
      out << "        <Attribute Name=\"" << f.name << "\" AttributeType=\"" << (f.components > 1 ? "Vector" : "Scalar")
          << "\" Center=\"Node\">\n";
      data_item(out, e, f, "          ");
      out << "        </Attribute>\n";
    }
    out << "      </Grid>\n";
  }
  out << "    </Grid>\n  </Domain>\n</Xdmf>\n";
  return out.str();
}

void write_xdmf(const std::filesystem::path& file, const std::vector<XdmfEntry>& frames) {
  write_file_atomic(file, xdmf_document(frames));
}

}  // namespace sph::io

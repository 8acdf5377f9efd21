#include "core/scene/scene_parser.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <sstream>

#include "core/particle_store.hpp"
#include "core/scene/scene_rules.hpp"

namespace sph::scene {

using detail::element;
using detail::fail;
using detail::join;
using detail::list;

namespace {



const char* type_name(const Json& j) {
  switch (j.type()) {
    case Json::value_t::object: return "an object";
    case Json::value_t::array: return "an array";
    case Json::value_t::string: return "a string";
    case Json::value_t::boolean: return "a boolean";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned: return "an integer";
    case Json::value_t::number_float: return "a number";
    case Json::value_t::null: return "null";
    default: return "an unsupported value";
  }
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}


/// Reads one JSON object: unknown keys are refused up front (with a suggestion), then typed accessors
/// read keys with defaults or as required.
class ObjectReader {
 public:
  ObjectReader(const Json& j, std::string path, std::vector<std::string> allowed, const std::string& what = "")
      : j_(j), path_(std::move(path)), allowed_(std::move(allowed)) {
    if (!j_.is_object()) fail(path_, std::string("must be an object (got ") + type_name(j_) + ")");
    for (const auto& item : j_.items()) {
      const std::string& key = item.key();
      if (std::find(allowed_.begin(), allowed_.end(), key) != allowed_.end()) continue;
      std::string rule = "unknown key";
      std::string best;
      std::size_t best_d = 3;
      for (const auto& a : allowed_) {
        const std::size_t d = edit_distance(key, a);
        if (d < best_d) best_d = d, best = a;
      }
      if (!best.empty()) rule += " (did you mean '" + best + "'?)";
      rule += "; allowed" + (what.empty() ? std::string() : " for " + what) + ": " + list(allowed_);
      fail(join(path_, key), rule);
    }
  }

  bool has(const char* key) const { return j_.contains(key); }
  std::string path(const char* key) const { return join(path_, key); }
  const Json& at(const char* key) const {
    if (!j_.contains(key)) fail(path(key), "missing required key");
    return j_.at(key);
  }

  double number(const char* key) const { return as_number(at(key), path(key)); }
  double number(const char* key, double fallback) const { return has(key) ? number(key) : fallback; }
  std::optional<double> optional_number(const char* key) const {
    return has(key) ? std::optional<double>(number(key)) : std::nullopt;
  }
  int integer(const char* key, int fallback) const {
    if (!has(key)) return fallback;
    const Json& v = at(key);
    if (!v.is_number_integer()) fail(path(key), std::string("must be an integer (got ") + type_name(v) + ")");
    const auto x = v.get<long long>();
    if (x < std::numeric_limits<int>::min() || x > std::numeric_limits<int>::max()) fail(path(key), "integer out of range");
    return static_cast<int>(x);
  }
  bool boolean(const char* key, bool fallback) const {
    if (!has(key)) return fallback;
    const Json& v = at(key);
    if (!v.is_boolean()) fail(path(key), std::string("must be true or false (got ") + type_name(v) + ")");
    return v.get<bool>();
  }
  std::string string(const char* key) const { return as_string(at(key), path(key)); }
  std::string string(const char* key, const std::string& fallback) const { return has(key) ? string(key) : fallback; }
  Vec<2> vec2(const char* key) const { return as_vec2(at(key), path(key)); }
  Vec<2> vec2(const char* key, const Vec<2>& fallback) const { return has(key) ? vec2(key) : fallback; }

  template <class E>
  E choice(const char* key, std::initializer_list<std::pair<const char*, E>> options, std::optional<E> fallback) const {
    if (!has(key)) {
      if (!fallback) fail(path(key), "missing required key");
      return *fallback;
    }
    return as_choice(at(key), path(key), options);
  }

  static double as_number(const Json& v, const std::string& path) {
    if (!v.is_number()) fail(path, std::string("must be a number (got ") + type_name(v) + ")");
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(path, "must be a finite number");
    return x;
  }
  static std::string as_string(const Json& v, const std::string& path) {
    if (!v.is_string()) fail(path, std::string("must be a string (got ") + type_name(v) + ")");
    return v.get<std::string>();
  }
  static Vec<2> as_vec2(const Json& v, const std::string& path) {
    if (!v.is_array() || v.size() != 2) {
      fail(path, std::string("must be an array of two numbers [x, y] (got ") +
                     (v.is_array() ? "an array of " + std::to_string(v.size()) : std::string(type_name(v))) + ")");
    }
    return Vec<2>(as_number(v[0], element(path, 0)), as_number(v[1], element(path, 1)));
  }
  template <class E>
  static E as_choice(const Json& v, const std::string& path, std::initializer_list<std::pair<const char*, E>> options) {
    const std::string s = as_string(v, path);
    std::vector<std::string> names;
    for (const auto& [name, value] : options) {
      if (s == name) return value;
      names.emplace_back(name);
    }
    fail(path, "must be one of: " + list(names) + " (got '" + s + "')");
  }

 private:
  const Json& j_;
  std::string path_;
  std::vector<std::string> allowed_;
};

const std::initializer_list<std::pair<const char*, Pattern>> kPatterns{{"aap", Pattern::aap}, {"rsp", Pattern::rsp}};

Rect parse_rect(const Json& j, const std::string& path) {
  ObjectReader r(j, path, {"lo", "hi"});
  return Rect{r.vec2("lo"), r.vec2("hi")};
}

Container parse_container(const Json& j, const std::string& path) {
  ObjectReader r(j, path, {"lo", "hi", "open_top", "outflow"});
  return Container{Rect{r.vec2("lo"), r.vec2("hi")}, r.boolean("open_top", true),
                   r.choice<Outflow>("outflow", {{"stop", Outflow::stop}, {"remove", Outflow::remove}}, Outflow::stop)};
}

FluidRegion parse_region(const Json& j, const std::string& path) {
  if (!j.is_object()) fail(path, std::string("must be an object (got ") + type_name(j) + ")");
  if (!j.contains("shape")) fail(join(path, "shape"), "missing required key (rectangle or circle)");
  FluidRegion f;
  f.shape = ObjectReader::as_choice<Shape>(j.at("shape"), join(path, "shape"),
                                           {{"rectangle", Shape::rectangle}, {"circle", Shape::circle}});
  std::vector<std::string> keys{"shape", "spacing", "level", "velocity", "hydrostatic", "surface"};
  if (f.shape == Shape::rectangle) {
    keys.insert(keys.begin() + 1, {"lo", "hi"});
  } else {
    keys.insert(keys.begin() + 1, {"centre", "radius"});
  }
  ObjectReader r(j, path, keys, std::string("a ") + to_string(f.shape));
  if (f.shape == Shape::rectangle) {
    f.rect = Rect{r.vec2("lo"), r.vec2("hi")};
  } else {
    f.centre = r.vec2("centre");
    f.radius = r.number("radius");
  }
  f.spacing = r.number("spacing");
  f.level = r.integer("level", 0);
  f.velocity = r.vec2("velocity", Vec<2>::Zero());
  f.hydrostatic = r.boolean("hydrostatic", false);
  f.surface = r.optional_number("surface");
  return f;
}

Material parse_material(const Json& j, const std::string& path) {
  ObjectReader r(j, path, {"rho0", "gamma", "c0", "mach_factor", "reference_speed", "reference_height"});
  Material m;
  m.rho0 = r.number("rho0");
  m.gamma = r.number("gamma", Material{}.gamma);
  m.c0 = r.optional_number("c0");
  m.mach_factor = r.optional_number("mach_factor");
  m.reference_speed = r.optional_number("reference_speed");
  m.reference_height = r.optional_number("reference_height");
  return m;
}

/// The merge test's key follows the split criterion's; its default is halfway to no refinement (half the
/// split speed, twice the split neighbour count), so a family does not flip between the two.
Coarsening parse_coarsening(const Json& j, const std::string& path, const Refinement& f) {
  if (!j.is_object()) fail(path, std::string("must be an object (got ") + type_name(j) + ")");
  std::vector<std::string> keys{"hold_time"};
  if (f.criterion == Criterion::velocity) keys.emplace_back("v_threshold");
  if (f.criterion == Criterion::few_neighbours) keys.emplace_back("min_neighbours");
  ObjectReader r(j, path, keys, std::string("criterion ") + to_string(f.criterion));
  Coarsening c;
  if (f.criterion == Criterion::velocity) c.v_threshold = r.number("v_threshold", 0.5 * f.v_threshold);
  if (f.criterion == Criterion::few_neighbours) c.min_neighbours = r.integer("min_neighbours", 2 * f.min_neighbours);
  c.hold_time = r.number("hold_time", Coarsening{}.hold_time);
  return c;
}

Refinement parse_refinement(const Json& j, const std::string& path) {
  if (!j.is_object()) fail(path, std::string("must be an object (got ") + type_name(j) + ")");
  Refinement f;
  f.criterion = j.contains("criterion")
                    ? ObjectReader::as_choice<Criterion>(j.at("criterion"), join(path, "criterion"),
                                                         {{"velocity", Criterion::velocity},
                                                          {"zone", Criterion::zone},
                                                          {"few_neighbours", Criterion::few_neighbours}})
                    : Criterion::velocity;
  std::vector<std::string> keys{"criterion", "pattern", "rsp_k", "check_interval", "max_level", "coarsening"};
  switch (f.criterion) {
    case Criterion::velocity: keys.emplace_back("v_threshold"); break;
    case Criterion::zone: keys.emplace_back("zone"); break;
    case Criterion::few_neighbours: keys.emplace_back("min_neighbours"); break;
  }
  ObjectReader r(j, path, keys, std::string("criterion ") + to_string(f.criterion));
  if (f.criterion == Criterion::velocity) f.v_threshold = r.number("v_threshold");
  if (f.criterion == Criterion::zone) f.zone = parse_rect(r.at("zone"), r.path("zone"));
  const Refinement d;
  if (f.criterion == Criterion::few_neighbours) f.min_neighbours = r.integer("min_neighbours", d.min_neighbours);
  f.pattern = r.choice<Pattern>("pattern", kPatterns, d.pattern);
  f.rsp_k = r.number("rsp_k", d.rsp_k);
  f.check_interval = r.integer("check_interval", d.check_interval);
  f.max_level = r.integer("max_level", d.max_level);
  if (r.has("coarsening")) f.coarsening = parse_coarsening(r.at("coarsening"), r.path("coarsening"), f);
  return f;
}

StaticRefinement parse_static_refinement(const Json& j, const std::string& path) {
  ObjectReader r(j, path, {"box", "pattern", "rsp_k"});
  StaticRefinement s;
  if (r.has("box")) s.box = parse_rect(r.at("box"), r.path("box"));
  s.pattern = r.choice<Pattern>("pattern", kPatterns, StaticRefinement{}.pattern);
  s.rsp_k = r.number("rsp_k", StaticRefinement{}.rsp_k);
  return s;
}

Effects parse_effects(const Json& j, const std::string& path) {
  ObjectReader r(j, path,
                 {"gravity", "artificial_viscosity", "artificial_stress", "density_diffusion", "lennard_jones_wall", "ghost_walls", "ghost_pressure", "refinement",
                  "static_refinement"});
  Effects e;
  if (r.has("gravity")) e.gravity = r.vec2("gravity");
  if (r.has("artificial_viscosity")) {
    ObjectReader v(r.at("artificial_viscosity"), r.path("artificial_viscosity"), {"alpha", "beta"});
    const ArtificialViscosity d;
    e.artificial_viscosity = ArtificialViscosity{v.number("alpha", d.alpha), v.number("beta", d.beta)};
  }
  if (r.has("artificial_stress")) {
    ObjectReader a(r.at("artificial_stress"), r.path("artificial_stress"), {"epsilon", "exponent"});
    const ArtificialStress d;
    e.artificial_stress = ArtificialStress{a.number("epsilon", d.epsilon), a.integer("exponent", d.exponent)};
  }
  if (r.has("density_diffusion")) {
    ObjectReader dd(r.at("density_diffusion"), r.path("density_diffusion"), {"delta"});
    e.density_diffusion = DensityDiffusion{dd.number("delta", DensityDiffusion{}.delta)};
  }
  if (r.has("lennard_jones_wall")) {
    ObjectReader w(r.at("lennard_jones_wall"), r.path("lennard_jones_wall"),
                   {"strength", "reference_height", "r0_factor", "spacing"});
    LennardJonesWall lj;
    lj.strength = w.optional_number("strength");
    lj.reference_height = w.optional_number("reference_height");
    lj.r0_factor = w.number("r0_factor", LennardJonesWall{}.r0_factor);
    lj.spacing = w.optional_number("spacing");
    e.lennard_jones_wall = lj;
  }
  if (r.has("ghost_walls")) {
    e.ghost_walls = r.choice<Slip>("ghost_walls", {{"free-slip", Slip::free_slip}, {"no-slip", Slip::no_slip}}, std::nullopt);
  }
  if (r.has("ghost_pressure")) {
    e.ghost_pressure = r.choice<GhostPressure>(
        "ghost_pressure", {{"hydrostatic", GhostPressure::hydrostatic}, {"mirrored", GhostPressure::mirrored}},
        GhostPressure::hydrostatic);
  }
  if (r.has("refinement")) e.refinement = parse_refinement(r.at("refinement"), r.path("refinement"));
  if (r.has("static_refinement")) {
    e.static_refinement = parse_static_refinement(r.at("static_refinement"), r.path("static_refinement"));
  }
  return e;
}

Time parse_time(const Json& j, const std::string& path) {
  ObjectReader r(j, path, {"end", "cfl", "output_interval", "dt_max", "stepping"});
  Time t;
  t.end = r.number("end");
  const Time d;
  t.cfl = r.number("cfl", d.cfl);
  t.output_interval = r.optional_number("output_interval");
  t.dt_max = r.number("dt_max", d.dt_max);
  t.stepping = r.choice<TimeStepping>(
      "stepping", {{"global", TimeStepping::global}, {"per_level", TimeStepping::per_level}}, d.stepping);
  return t;
}

Probe parse_probe(const Json& j, const std::string& path) {
  if (!j.is_object()) fail(path, std::string("must be an object (got ") + type_name(j) + ")");
  if (!j.contains("type")) fail(join(path, "type"), "missing required key");
  Probe p;
  p.kind = ObjectReader::as_choice<ProbeKind>(j.at("type"), join(path, "type"),
                                              {{"water_height", ProbeKind::water_height},
                                               {"surge_front", ProbeKind::surge_front},
                                               {"surface_elevation", ProbeKind::surface_elevation},
                                               {"pressure", ProbeKind::pressure}});
  std::vector<std::string> keys{"type", "name"};
  switch (p.kind) {
    case ProbeKind::water_height: keys.insert(keys.end(), {"x", "band"}); break;
    case ProbeKind::surface_elevation: keys.insert(keys.end(), {"x", "band", "datum"}); break;
    case ProbeKind::surge_front: keys.insert(keys.end(), {"origin"}); break;
    case ProbeKind::pressure: keys.insert(keys.end(), {"position"}); break;
  }
  ObjectReader r(j, path, keys, std::string("a ") + to_string(p.kind) + " probe");
  p.name = r.string("name", "");
  if (p.kind == ProbeKind::water_height || p.kind == ProbeKind::surface_elevation) {
    p.x = r.number("x");
    p.band = r.optional_number("band");
  }
  if (p.kind == ProbeKind::surface_elevation) p.datum = r.number("datum", 0.0);
  if (p.kind == ProbeKind::surge_front) p.origin = r.optional_number("origin");
  if (p.kind == ProbeKind::pressure) p.position = r.vec2("position");
  return p;
}

Output parse_output(const Json& j, const std::string& path) {
  ObjectReader r(j, path, {"folder", "frames", "frame_interval", "fields"});
  Output o;
  o.folder = r.string("folder", "");
  o.frames = r.boolean("frames", true);
  o.frame_interval = r.optional_number("frame_interval");
  if (r.has("fields")) {
    const Json& f = r.at("fields");
    if (!f.is_array()) fail(r.path("fields"), std::string("must be an array of field names (got ") + type_name(f) + ")");
    for (std::size_t i = 0; i < f.size(); ++i) o.fields.push_back(ObjectReader::as_string(f[i], element(r.path("fields"), i)));
  }
  return o;
}

}  // namespace

// ---- JSON text ------------------------------------------------------------------------------------------------

Json parse_json_text(const std::string& text, const std::string& source) {
  // The parser callback tracks the key path so that a duplicate key (which JSON parsers silently
  // resolve to one of the values) is refused by name.
  struct Frame {
    bool array = false;
    std::string key;
    std::size_t index = 0;
    bool started = false;
    std::vector<std::string> keys;
  };
  std::vector<Frame> stack;
  auto path_to = [&](std::size_t depth) {
    std::string p;
    for (std::size_t k = 0; k < depth; ++k) p = stack[k].array ? element(p, stack[k].index) : join(p, stack[k].key);
    return p;
  };
  auto element_begins = [&] {
    if (!stack.empty() && stack.back().array) {
      if (stack.back().started) ++stack.back().index;
      stack.back().started = true;
    }
  };
  const Json::parser_callback_t callback = [&](int, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
        element_begins();
        stack.push_back(Frame{});
        break;
      case Json::parse_event_t::array_start:
        element_begins();
        stack.push_back(Frame{true, "", 0, false, {}});
        break;
      case Json::parse_event_t::key: {
        Frame& f = stack.back();
        const auto key = parsed.get<std::string>();
        if (std::find(f.keys.begin(), f.keys.end(), key) != f.keys.end()) {
          f.key = key;
          fail(path_to(stack.size()), "duplicate key");
        }
        f.keys.push_back(key);
        f.key = key;
        break;
      }
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        if (!stack.empty()) stack.pop_back();
        break;
      case Json::parse_event_t::value:
        element_begins();
        break;
    }
    return true;
  };
  try {
    return Json::parse(text, callback, /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const Json::exception& e) {
    // Syntax errors, and also numbers that do not fit a double (out_of_range, e.g. 1e400): both are malformed
    // text, named with the key path reached so far.
    std::string what = e.what();
    if (what.rfind("[json.exception.", 0) == 0) what = what.substr(what.find(']') + 2);
    const std::string at = path_to(stack.size());
    fail(source, "malformed JSON: " + what + (at.empty() ? std::string() : " (in " + at + ")"));
  }
}

Json read_json_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) fail(file.string(), "is a directory, not a scene file");
  if (!std::filesystem::is_regular_file(file, ec)) fail(file.string(), "no such scene file");
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file.string(), "cannot read the scene file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_json_text(text.str(), file.string());
}

void apply_override(Json& doc, const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) fail("--set", "expected key.path=value (got '" + assignment + "')");
  const std::string key_path = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  const std::string where = "--set " + key_path;

  // Split "a.b[2].c" / "a.b.2.c" into segments.
  std::vector<std::string> segments;
  std::string cur;
  for (std::size_t i = 0; i < key_path.size(); ++i) {
    const char c = key_path[i];
    if (c == '.') {
      segments.push_back(cur);
      cur.clear();
    } else if (c == '[') {
      const std::size_t close = key_path.find(']', i);
      if (close == std::string::npos) fail(where, "unbalanced '['");
      segments.push_back(cur);
      cur = key_path.substr(i + 1, close - i - 1);
      i = close;
    } else {
      cur += c;
    }
  }
  segments.push_back(cur);
  segments.erase(std::remove(segments.begin(), segments.end(), std::string()), segments.end());
  if (segments.empty()) fail(where, "empty key path");

  Json value;
  try {
    value = Json::parse(text);
  } catch (const Json::parse_error&) {
    value = text;  // a bare word: a string
  }

  auto is_index = [](const std::string& s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  Json* node = &doc;
  std::string walked;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const std::string& seg = segments[k];
    const bool last = k + 1 == segments.size();
    if (node->is_array()) {
      if (!is_index(seg)) fail(where, (walked.empty() ? "(root)" : walked) + " is an array: '" + seg + "' is not an index");
      const std::size_t i = std::stoul(seg);
      if (i >= node->size()) {
        fail(where, "index " + seg + " is out of range (" + walked + " has " + std::to_string(node->size()) + " elements)");
      }
      walked = element(walked, i);
      if (last) {
        if (value.is_null()) {
          node->erase(i);
        } else {
          (*node)[i] = value;
        }
        return;
      }
      node = &(*node)[i];
    } else {
      if (!node->is_object()) fail(where, (walked.empty() ? "(root)" : walked) + " is not an object");
      walked = join(walked, seg);
      if (last) {
        if (value.is_null()) {
          node->erase(seg);
        } else {
          (*node)[seg] = value;
        }
        return;
      }
      if (!node->contains(seg)) (*node)[seg] = Json::object();
      node = &(*node)[seg];
    }
  }
}

// ---- Scene <-> JSON -------------------------------------------------------------------------------------------

Scene scene_from_json(const Json& doc) {
  ObjectReader r(doc, "",
                 {"name", "description", "container", "obstacles", "fluid", "h_factor", "material", "effects", "time",
                  "probes", "output"});
  Scene s;
  s.name = r.string("name", "scene");
  s.description = r.string("description", "");
  s.container = parse_container(r.at("container"), "container");
  if (r.has("obstacles")) {
    const Json& o = r.at("obstacles");
    if (!o.is_array()) fail("obstacles", std::string("must be an array of boxes (got ") + type_name(o) + ")");
    for (std::size_t i = 0; i < o.size(); ++i) s.obstacles.push_back(parse_rect(o[i], element("obstacles", i)));
  }
  const Json& fluid = r.at("fluid");
  if (!fluid.is_array()) fail("fluid", std::string("must be an array of regions (got ") + type_name(fluid) + ")");
  for (std::size_t i = 0; i < fluid.size(); ++i) s.fluid.push_back(parse_region(fluid[i], element("fluid", i)));
  s.h_factor = r.number("h_factor", Scene{}.h_factor);
  s.material = parse_material(r.at("material"), "material");
  if (r.has("effects")) s.effects = parse_effects(r.at("effects"), "effects");
  s.time = parse_time(r.at("time"), "time");
  if (r.has("probes")) {
    const Json& p = r.at("probes");
    if (!p.is_array()) fail("probes", std::string("must be an array of probes (got ") + type_name(p) + ")");
    for (std::size_t i = 0; i < p.size(); ++i) s.probes.push_back(parse_probe(p[i], element("probes", i)));
  }
  // Default probe names (kind and index) before validation, so that they are checked for uniqueness too.
  for (std::size_t i = 0; i < s.probes.size(); ++i) {
    if (s.probes[i].name.empty() && !(r.has("probes") && r.at("probes")[i].contains("name"))) {
      s.probes[i].name = std::string(to_string(s.probes[i].kind)) + "_" + std::to_string(i);
    }
  }
  if (r.has("output")) s.output = parse_output(r.at("output"), "output");
  validate_scene(s);
  return s;
}

Scene load_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  Json doc = read_json_file(file);
  for (const auto& o : overrides) apply_override(doc, o);
  if (doc.is_object() && !doc.contains("name")) {
    std::string stem = file.stem().string();
    for (char& c : stem) {
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) c = '_';
    }
    doc["name"] = stem.empty() ? std::string("scene") : stem;
  }
  return scene_from_json(doc);
}

}  // namespace sph::scene

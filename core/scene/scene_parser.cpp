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

namespace sph::scene {

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& rule) { throw SceneError(path, rule); }

std::string join(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
std::string element(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }

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

std::string list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
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
  ObjectReader r(j, path, {"lo", "hi", "open_top"});
  return Container{Rect{r.vec2("lo"), r.vec2("hi")}, r.boolean("open_top", true)};
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
  m.gamma = r.number("gamma", 7.0);
  m.c0 = r.optional_number("c0");
  m.mach_factor = r.optional_number("mach_factor");
  m.reference_speed = r.optional_number("reference_speed");
  m.reference_height = r.optional_number("reference_height");
  return m;
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
  std::vector<std::string> keys{"criterion", "pattern", "rsp_k", "check_interval", "max_level"};
  switch (f.criterion) {
    case Criterion::velocity: keys.emplace_back("v_threshold"); break;
    case Criterion::zone: keys.emplace_back("zone"); break;
    case Criterion::few_neighbours: keys.emplace_back("min_neighbours"); break;
  }
  ObjectReader r(j, path, keys, std::string("criterion ") + to_string(f.criterion));
  if (f.criterion == Criterion::velocity) f.v_threshold = r.number("v_threshold");
  if (f.criterion == Criterion::zone) f.zone = parse_rect(r.at("zone"), r.path("zone"));
  if (f.criterion == Criterion::few_neighbours) f.min_neighbours = r.integer("min_neighbours", 8);
  f.pattern = r.choice<Pattern>("pattern", kPatterns, Pattern::aap);
  f.rsp_k = r.number("rsp_k", 1.0);
  f.check_interval = r.integer("check_interval", 100);
  f.max_level = r.integer("max_level", 1);
  return f;
}

StaticRefinement parse_static_refinement(const Json& j, const std::string& path) {
  ObjectReader r(j, path, {"box", "pattern", "rsp_k"});
  StaticRefinement s;
  if (r.has("box")) s.box = parse_rect(r.at("box"), r.path("box"));
  s.pattern = r.choice<Pattern>("pattern", kPatterns, Pattern::aap);
  s.rsp_k = r.number("rsp_k", 1.0);
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
    e.artificial_viscosity = ArtificialViscosity{v.number("alpha", 0.02), v.number("beta", 0.0)};
  }
  if (r.has("artificial_stress")) {
    ObjectReader a(r.at("artificial_stress"), r.path("artificial_stress"), {"epsilon", "exponent"});
    e.artificial_stress = ArtificialStress{a.number("epsilon", 0.2), a.integer("exponent", 4)};
  }
  if (r.has("density_diffusion")) {
    ObjectReader dd(r.at("density_diffusion"), r.path("density_diffusion"), {"delta"});
    e.density_diffusion = DensityDiffusion{dd.number("delta", 0.1)};
  }
  if (r.has("lennard_jones_wall")) {
    ObjectReader w(r.at("lennard_jones_wall"), r.path("lennard_jones_wall"),
                   {"strength", "reference_height", "r0_factor", "spacing"});
    LennardJonesWall lj;
    lj.strength = w.optional_number("strength");
    lj.reference_height = w.optional_number("reference_height");
    lj.r0_factor = w.number("r0_factor", 0.5);
    lj.spacing = w.optional_number("spacing");
    e.lennard_jones_wall = lj;
  }
  if (r.has("ghost_walls")) {
    e.ghost_walls = r.choice<Slip>("ghost_walls", {{"free-slip", Slip::free_slip}, {"no-slip", Slip::no_slip}}, std::nullopt);
  }
  if (r.has("ghost_pressure")) {
    e.ghost_pressure_mirrored = r.choice<bool>("ghost_pressure", {{"hydrostatic", false}, {"mirrored", true}}, false);
  }
  if (r.has("refinement")) e.refinement = parse_refinement(r.at("refinement"), r.path("refinement"));
  if (r.has("static_refinement")) {
    e.static_refinement = parse_static_refinement(r.at("static_refinement"), r.path("static_refinement"));
  }
  return e;
}

Time parse_time(const Json& j, const std::string& path) {
  ObjectReader r(j, path, {"end", "cfl", "output_interval", "dt_max"});
  Time t;
  t.end = r.number("end");
  t.cfl = r.number("cfl", 0.2);
  t.output_interval = r.optional_number("output_interval");
  t.dt_max = r.number("dt_max", 1.0);
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

// ---- value rules -------------------------------------------------------------------------------------------

std::string num(double x) {
  std::ostringstream s;
  s.precision(6);
  s << x;
  return s.str();
}

void positive(double x, const std::string& path, const std::string& what = "must be positive") {
  if (!(x > 0.0)) fail(path, what + " (got " + num(x) + ")");
}

void valid_rect(const Rect& r, const std::string& path) {
  if (!(r.hi[0] > r.lo[0] && r.hi[1] > r.lo[1])) {
    fail(join(path, "hi"), "must be greater than lo in x and in y (lo = [" + num(r.lo[0]) + ", " + num(r.lo[1]) +
                               "], hi = [" + num(r.hi[0]) + ", " + num(r.hi[1]) + "])");
  }
}

bool rects_overlap(const Rect& a, const Rect& b) {
  return a.lo[0] < b.hi[0] && b.lo[0] < a.hi[0] && a.lo[1] < b.hi[1] && b.lo[1] < a.hi[1];
}

double distance_to_rect(const Vec<2>& p, const Rect& r) {
  const double dx = std::max({r.lo[0] - p[0], 0.0, p[0] - r.hi[0]});
  const double dy = std::max({r.lo[1] - p[1], 0.0, p[1] - r.hi[1]});
  return std::hypot(dx, dy);
}

constexpr double kTol = 1e-9;
constexpr int kMaxLevel = 8;
constexpr double kMaxParticles = 5.0e7;

bool inside(const Rect& inner, const Rect& outer) {
  const double t = kTol * std::max(1.0, (outer.hi - outer.lo).cwiseAbs().maxCoeff());
  return inner.lo[0] >= outer.lo[0] - t && inner.lo[1] >= outer.lo[1] - t && inner.hi[0] <= outer.hi[0] + t &&
         inner.hi[1] <= outer.hi[1] + t;
}

Rect bounds(const FluidRegion& f) {
  if (f.shape == Shape::rectangle) return f.rect;
  return Rect{f.centre - Vec<2>::Constant(f.radius), f.centre + Vec<2>::Constant(f.radius)};
}

double estimated_particles(const FluidRegion& f) {
  const double d = f.lattice_spacing();
  if (f.shape == Shape::rectangle) {
    return std::floor((f.rect.hi[0] - f.rect.lo[0]) / d + 1e-9) * std::floor((f.rect.hi[1] - f.rect.lo[1]) / d + 1e-9);
  }
  return std::numbers::pi * (f.radius / d + 1.0) * (f.radius / d + 1.0);
}

void validate_region(const Scene& s, const FluidRegion& f, const std::string& path) {
  if (f.shape == Shape::rectangle) {
    valid_rect(f.rect, path);
  } else {
    positive(f.radius, join(path, "radius"));
  }
  positive(f.spacing, join(path, "spacing"));
  if (f.level < 0 || f.level > kMaxLevel) {
    fail(join(path, "level"), "must be between 0 and " + std::to_string(kMaxLevel) + " (got " + std::to_string(f.level) + ")");
  }
  const double d = f.lattice_spacing();
  if (!inside(bounds(f), s.container.box)) {
    fail(path, std::string("the ") + to_string(f.shape) + " reaches outside the container");
  }
  for (std::size_t k = 0; k < s.obstacles.size(); ++k) {
    const Rect& o = s.obstacles[k];
    const bool overlap = f.shape == Shape::rectangle ? rects_overlap(f.rect, o)
                                                     : distance_to_rect(f.centre, o) < f.radius - kTol;
    if (overlap) fail(path, "overlaps obstacles[" + std::to_string(k) + "] (fluid must start outside every obstacle)");
  }
  const double n = estimated_particles(f);
  if (f.shape == Shape::rectangle && n < 1.0) {
    fail(join(path, "spacing"), "the rectangle holds no particle at lattice spacing " + num(d) + " m");
  }
  if (n > kMaxParticles) {
    fail(join(path, "spacing"), "would create about " + num(n) + " particles (limit " + num(kMaxParticles) + ")");
  }
  if (f.hydrostatic) {
    if (!s.effects.gravity) fail(join(path, "hydrostatic"), "needs effects.gravity");
    if ((*s.effects.gravity)[0] != 0.0 || !((*s.effects.gravity)[1] < 0.0)) {
      fail(join(path, "hydrostatic"), "needs gravity pointing along -y ([0, -g])");
    }
    if (f.shape == Shape::circle && !f.surface) fail(join(path, "surface"), "required for a hydrostatic circle");
  } else if (f.surface) {
    fail(join(path, "surface"), "only used with \"hydrostatic\": true");
  }
}

void validate_probe(const Scene& s, const Probe& p, const std::string& path) {
  const Rect& c = s.container.box;
  if (p.kind == ProbeKind::water_height || p.kind == ProbeKind::surface_elevation) {
    if (p.x < c.lo[0] - kTol || p.x > c.hi[0] + kTol) fail(join(path, "x"), "must lie within the container's x range");
    if (p.band) positive(*p.band, join(path, "band"));
  }
  if (p.kind == ProbeKind::pressure && !inside(Rect{p.position, p.position}, c)) {
    fail(join(path, "position"), "must lie inside the container");
  }
  if (p.name.empty()) fail(join(path, "name"), "must not be empty");
  for (char ch : p.name) {
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_')) {
      fail(join(path, "name"), "may hold only letters, digits and '_' (it names a CSV column; got '" + p.name + "')");
    }
  }
}

}  // namespace

// ---- derived quantities ---------------------------------------------------------------------------------------

double FluidRegion::lattice_spacing() const { return spacing / std::pow(2.0, level); }

double gravity_magnitude(const Scene& s) {
  if (!s.effects.gravity) return 0.0;
  const Vec<2>& g = *s.effects.gravity;
  return g[0] == 0.0 ? std::abs(g[1]) : g.norm();
}

double sound_speed(const Scene& s) {
  const Material& m = s.material;
  if (m.c0) return *m.c0;
  const double factor = m.mach_factor.value_or(10.0);
  if (m.reference_speed) return factor * *m.reference_speed;
  if (m.reference_height) return factor * std::sqrt(2.0 * gravity_magnitude(s) * *m.reference_height);
  return 0.0;
}

namespace {
int region_finest_level(const Scene& s, const FluidRegion& f) {
  int l = f.level + (s.effects.static_refinement ? 1 : 0);
  if (s.effects.refinement) l = std::max(l, s.effects.refinement->max_level);
  return l;
}
}  // namespace

int finest_level(const Scene& s) {
  int l = 0;
  for (const auto& f : s.fluid) l = std::max(l, region_finest_level(s, f));
  return l;
}

double finest_spacing(const Scene& s) {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& f : s.fluid) d = std::min(d, f.spacing / std::pow(2.0, region_finest_level(s, f)));
  return d;
}

double coarsest_spacing(const Scene& s) {
  double d = 0.0;
  for (const auto& f : s.fluid) d = std::max(d, f.spacing);
  return d;
}

double wall_spacing(const Scene& s) {
  if (s.effects.lennard_jones_wall && s.effects.lennard_jones_wall->spacing) return *s.effects.lennard_jones_wall->spacing;
  return finest_spacing(s) / 2;
}

double estimated_particles(const Scene& s) {
  double fluid = 0.0;
  for (const auto& f : s.fluid) fluid += estimated_particles(f);
  if (s.effects.static_refinement) fluid *= 4.0;
  double walls = 0.0;
  if (s.effects.lennard_jones_wall) {
    double extent = 2.0 * (s.container.box.hi - s.container.box.lo).sum();
    for (const auto& o : s.obstacles) extent += 2.0 * (o.hi - o.lo).sum();
    walls = extent / wall_spacing(s);
  }
  return fluid + walls;
}

double lennard_jones_strength(const Scene& s) {
  if (!s.effects.lennard_jones_wall) return 0.0;
  const LennardJonesWall& w = *s.effects.lennard_jones_wall;
  if (w.strength) return *w.strength;
  return 5.0 * gravity_magnitude(s) * w.reference_height.value_or(0.0);
}

const char* to_string(Shape v) { return v == Shape::rectangle ? "rectangle" : "circle"; }
const char* to_string(Slip v) { return v == Slip::free_slip ? "free-slip" : "no-slip"; }
const char* to_string(Criterion v) {
  switch (v) {
    case Criterion::velocity: return "velocity";
    case Criterion::zone: return "zone";
    case Criterion::few_neighbours: return "few_neighbours";
  }
  return "?";
}
const char* to_string(Pattern v) { return v == Pattern::aap ? "aap" : "rsp"; }
const char* to_string(ProbeKind v) {
  switch (v) {
    case ProbeKind::water_height: return "water_height";
    case ProbeKind::surge_front: return "surge_front";
    case ProbeKind::surface_elevation: return "surface_elevation";
    case ProbeKind::pressure: return "pressure";
  }
  return "?";
}

std::vector<std::string> particle_field_names() {
  std::vector<std::string> names;
  ParticleStore<2> store;
  store.for_each_field([&](const auto& f) { names.emplace_back(f.name()); });
  return names;
}

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
  s.h_factor = r.number("h_factor", 1.2);
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

void validate_scene(const Scene& s) {
  if (s.name.empty()) fail("name", "must not be empty");
  for (char ch : s.name) {
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.')) {
      fail("name", "may hold only letters, digits, '_', '-' and '.' (it names the output folder; got '" + s.name + "')");
    }
  }
  valid_rect(s.container.box, "container");
  for (std::size_t k = 0; k < s.obstacles.size(); ++k) {
    const std::string path = element("obstacles", k);
    valid_rect(s.obstacles[k], path);
    if (!inside(s.obstacles[k], s.container.box)) fail(path, "must lie inside the container");
  }

  // Material and effects come first: the regions' rules (hydrostatic) depend on gravity.
  const Material& m = s.material;
  positive(m.rho0, "material.rho0");
  if (!(m.gamma >= 1.0)) fail("material.gamma", "must be at least 1 (got " + num(m.gamma) + ")");
  if (m.c0) {
    positive(*m.c0, "material.c0");
    if (m.mach_factor || m.reference_speed || m.reference_height) {
      fail("material", "give either c0, or mach_factor with reference_speed or reference_height, not both");
    }
  } else {
    if (m.mach_factor) positive(*m.mach_factor, "material.mach_factor");
    if (m.reference_speed && m.reference_height) {
      fail("material", "give reference_speed or reference_height, not both");
    }
    if (m.reference_speed) {
      positive(*m.reference_speed, "material.reference_speed");
    } else if (m.reference_height) {
      positive(*m.reference_height, "material.reference_height");
      if (gravity_magnitude(s) <= 0.0) fail("material.reference_height", "needs effects.gravity (v_ref = sqrt(2 g H))");
    } else {
      fail("material.c0", "missing required key (or give mach_factor with reference_speed or reference_height)");
    }
  }
  if (!(s.h_factor >= 0.5 && s.h_factor <= 3.0)) fail("h_factor", "must be between 0.5 and 3 (got " + num(s.h_factor) + ")");

  const Effects& e = s.effects;
  if (e.gravity && !(e.gravity->norm() > 0.0)) fail("effects.gravity", "must not be zero (remove the key to turn gravity off)");
  if (e.artificial_viscosity) {
    if (!(e.artificial_viscosity->alpha >= 0.0)) fail("effects.artificial_viscosity.alpha", "must not be negative");
    if (!(e.artificial_viscosity->beta >= 0.0)) fail("effects.artificial_viscosity.beta", "must not be negative");
  }
  if (e.artificial_stress) {
    const double eps = e.artificial_stress->epsilon;
    if (!(eps > 0.0 && eps <= 1.0)) fail("effects.artificial_stress.epsilon", "must be in (0, 1] (got " + num(eps) + ")");
    const int n = e.artificial_stress->exponent;
    if (n < 1 || n > 16) fail("effects.artificial_stress.exponent", "must be between 1 and 16 (got " + std::to_string(n) + ")");
  }
  if (e.density_diffusion) {
    const double delta = e.density_diffusion->delta;
    if (!(delta > 0.0 && delta <= 1.0)) fail("effects.density_diffusion.delta", "must be in (0, 1] (got " + num(delta) + ")");
  }
  if (e.refinement) {
    const Refinement& r = *e.refinement;
    const std::string p = "effects.refinement";
    if (r.criterion == Criterion::velocity) positive(r.v_threshold, p + ".v_threshold");
    if (r.criterion == Criterion::zone) valid_rect(r.zone, p + ".zone");
    if (r.criterion == Criterion::few_neighbours && r.min_neighbours < 1) fail(p + ".min_neighbours", "must be at least 1");
    if (!(r.rsp_k > 0.0 && r.rsp_k <= 2.0)) fail(p + ".rsp_k", "must be in (0, 2] (got " + num(r.rsp_k) + ")");
    if (r.check_interval < 1) fail(p + ".check_interval", "must be at least 1 step");
    if (r.max_level < 1 || r.max_level > kMaxLevel) {
      fail(p + ".max_level", "must be between 1 and " + std::to_string(kMaxLevel) + " (got " + std::to_string(r.max_level) + ")");
    }
  }
  if (e.static_refinement) {
    if (e.static_refinement->box) valid_rect(*e.static_refinement->box, "effects.static_refinement.box");
    const double k = e.static_refinement->rsp_k;
    if (!(k > 0.0 && k <= 2.0)) fail("effects.static_refinement.rsp_k", "must be in (0, 2] (got " + num(k) + ")");
  }

  if (s.fluid.empty()) fail("fluid", "at least one fluid region is required");
  double total = 0.0;
  for (std::size_t k = 0; k < s.fluid.size(); ++k) {
    validate_region(s, s.fluid[k], element("fluid", k));
    total += estimated_particles(s.fluid[k]);
  }
  if (total > kMaxParticles) fail("fluid", "the regions would create about " + num(total) + " particles (limit " + num(kMaxParticles) + ")");

  if (e.refinement) {
    int start = 0;
    for (const auto& f : s.fluid) start = std::max(start, f.level + (e.static_refinement ? 1 : 0));
    if (e.refinement->max_level <= start) {
      fail("effects.refinement.max_level",
           "must exceed the particles' starting level " + std::to_string(start) + ", or nothing is ever refined");
    }
  }
  if (e.lennard_jones_wall) {
    const LennardJonesWall& w = *e.lennard_jones_wall;
    const std::string p = "effects.lennard_jones_wall";
    if (w.strength && w.reference_height) fail(p, "give strength or reference_height, not both");
    if (w.strength) {
      positive(*w.strength, p + ".strength");
    } else if (w.reference_height) {
      positive(*w.reference_height, p + ".reference_height");
      if (gravity_magnitude(s) <= 0.0) fail(p + ".reference_height", "needs effects.gravity (D = 5 g H)");
    } else {
      fail(p + ".strength", "missing required key (or give reference_height, D = 5 g H)");
    }
    if (!(w.r0_factor > 0.0 && w.r0_factor <= 2.0)) fail(p + ".r0_factor", "must be in (0, 2] (got " + num(w.r0_factor) + ")");
    if (w.spacing) positive(*w.spacing, p + ".spacing");
    // Resolution rule: at the finest level the scene can reach (spacing d), the repulsion range r0 =
    // r0_factor d must cover the wall-particle spacing, or particles of that level slip between them.
    const double d = finest_spacing(s);
    const double r0 = w.r0_factor * d;
    const double ws = wall_spacing(s);
    if (ws > r0 * (1.0 + 1e-9)) {
      // With an explicit spacing, a coarser finest level (max_level) or a finer wall spacing fixes it; with the
      // default spacing (d_min / 2) only r0_factor can be at fault.
      fail(w.spacing ? p + ".spacing" : p + ".r0_factor",
           "the walls cannot resolve level " + std::to_string(finest_level(s)) + ": wall-particle spacing " + num(ws) +
               " m exceeds the repulsion range r0 = r0_factor * d = " + num(r0) + " m of its particles (d = " + num(d) +
               (w.spacing ? " m); lower the refinement level or the wall spacing" : " m); raise r0_factor to 0.5 or more"));
    }
    double extent = 2.0 * (s.container.box.hi - s.container.box.lo).sum();
    for (const auto& o : s.obstacles) extent += 2.0 * (o.hi - o.lo).sum();
    if (extent / ws > kMaxParticles) fail(p + ".spacing", "would create more than " + num(kMaxParticles) + " wall particles");
  }

  const Time& t = s.time;
  positive(t.end, "time.end");
  if (!(t.cfl > 0.0 && t.cfl <= 1.0)) fail("time.cfl", "must be in (0, 1] (got " + num(t.cfl) + ")");
  positive(t.dt_max, "time.dt_max");
  if (t.end / t.dt_max > 1e9) fail("time.dt_max", "would take more than 1e9 steps to reach time.end");
  if (t.output_interval) {
    positive(*t.output_interval, "time.output_interval");
    if (t.end / *t.output_interval > 1e6) fail("time.output_interval", "would write more than a million outputs");
  }

  for (std::size_t k = 0; k < s.probes.size(); ++k) {
    validate_probe(s, s.probes[k], element("probes", k));
    for (std::size_t j = 0; j < k; ++j) {
      if (s.probes[j].name == s.probes[k].name) fail(element("probes", k) + ".name", "duplicate probe name '" + s.probes[k].name + "'");
    }
  }

  const Output& o = s.output;
  if (o.frame_interval) {
    positive(*o.frame_interval, "output.frame_interval");
    if (t.end / *o.frame_interval > 1e6) fail("output.frame_interval", "would write more than a million frames");
  }
  const auto names = particle_field_names();
  for (std::size_t k = 0; k < o.fields.size(); ++k) {
    if (std::find(names.begin(), names.end(), o.fields[k]) == names.end()) {
      fail(element("output.fields", k), "unknown field '" + o.fields[k] + "'; fields: " + list(names));
    }
  }
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

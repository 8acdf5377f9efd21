// The scene's JSON writer: scene_to_json (declared in scene_parser.hpp), the inverse of scene_from_json for
// every accepted scene (tested by the round-trip tests and the fuzzer).
#include "core/scene/scene_parser.hpp"

namespace sph::scene {

namespace {

Json vec(const Vec<2>& v) { return Json::array({v[0], v[1]}); }
Json rect(const Rect& r) { return Json{{"lo", vec(r.lo)}, {"hi", vec(r.hi)}}; }

}  // namespace

Json scene_to_json(const Scene& s) {
  Json j;
  j["name"] = s.name;
  if (!s.description.empty()) j["description"] = s.description;
  j["container"] = Json{{"lo", vec(s.container.box.lo)}, {"hi", vec(s.container.box.hi)}, {"open_top", s.container.open_top},
                        {"outflow", to_string(s.container.outflow)}};
  if (!s.obstacles.empty()) {
    j["obstacles"] = Json::array();
    for (const auto& o : s.obstacles) j["obstacles"].push_back(rect(o));
  }
  j["fluid"] = Json::array();
  for (const auto& f : s.fluid) {
    Json r;
    r["shape"] = to_string(f.shape);
    if (f.shape == Shape::rectangle) {
      r["lo"] = vec(f.rect.lo);
      r["hi"] = vec(f.rect.hi);
    } else {
      r["centre"] = vec(f.centre);
      r["radius"] = f.radius;
    }
    r["spacing"] = f.spacing;
    r["level"] = f.level;
    r["velocity"] = vec(f.velocity);
    r["hydrostatic"] = f.hydrostatic;
    if (f.surface) r["surface"] = *f.surface;
    j["fluid"].push_back(r);
  }
  j["h_factor"] = s.h_factor;
  Json m{{"rho0", s.material.rho0}, {"gamma", s.material.gamma}};
  if (s.material.c0) m["c0"] = *s.material.c0;
  if (s.material.mach_factor) m["mach_factor"] = *s.material.mach_factor;
  if (s.material.reference_speed) m["reference_speed"] = *s.material.reference_speed;
  if (s.material.reference_height) m["reference_height"] = *s.material.reference_height;
  j["material"] = m;

  Json e = Json::object();
  const Effects& fx = s.effects;
  if (fx.gravity) e["gravity"] = vec(*fx.gravity);
  if (fx.artificial_viscosity) {
    e["artificial_viscosity"] = Json{{"alpha", fx.artificial_viscosity->alpha}, {"beta", fx.artificial_viscosity->beta}};
  }
  if (fx.artificial_stress) {
    e["artificial_stress"] = Json{{"epsilon", fx.artificial_stress->epsilon}, {"exponent", fx.artificial_stress->exponent}};
  }
  if (fx.density_diffusion) e["density_diffusion"] = Json{{"delta", fx.density_diffusion->delta}};
  if (fx.lennard_jones_wall) {
    Json w;
    if (fx.lennard_jones_wall->strength) w["strength"] = *fx.lennard_jones_wall->strength;
    if (fx.lennard_jones_wall->reference_height) w["reference_height"] = *fx.lennard_jones_wall->reference_height;
    w["r0_factor"] = fx.lennard_jones_wall->r0_factor;
    if (fx.lennard_jones_wall->spacing) w["spacing"] = *fx.lennard_jones_wall->spacing;
    e["lennard_jones_wall"] = w;
  }
  if (fx.ghost_walls) e["ghost_walls"] = to_string(*fx.ghost_walls);
  e["ghost_pressure"] = to_string(fx.ghost_pressure);
  if (fx.refinement) {
    const Refinement& r = *fx.refinement;
    Json o;
    o["criterion"] = to_string(r.criterion);
    if (r.criterion == Criterion::velocity) o["v_threshold"] = r.v_threshold;
    if (r.criterion == Criterion::zone) o["zone"] = rect(r.zone);
    if (r.criterion == Criterion::few_neighbours) o["min_neighbours"] = r.min_neighbours;
    o["pattern"] = to_string(r.pattern);
    o["rsp_k"] = r.rsp_k;
    o["check_interval"] = r.check_interval;
    o["max_level"] = r.max_level;
    if (const auto& c = r.coarsening) {
      Json co;
      if (r.criterion == Criterion::velocity) co["v_threshold"] = c->v_threshold;
      if (r.criterion == Criterion::few_neighbours) co["min_neighbours"] = c->min_neighbours;
      co["hold_time"] = c->hold_time;
      o["coarsening"] = co;
    }
    e["refinement"] = o;
  }
  if (fx.static_refinement) {
    Json o;
    if (fx.static_refinement->box) o["box"] = rect(*fx.static_refinement->box);
    o["pattern"] = to_string(fx.static_refinement->pattern);
    o["rsp_k"] = fx.static_refinement->rsp_k;
    e["static_refinement"] = o;
  }
  j["effects"] = e;

  Json t{{"end", s.time.end}, {"cfl", s.time.cfl}};
  if (s.time.output_interval) t["output_interval"] = *s.time.output_interval;
  t["dt_max"] = s.time.dt_max;
  t["stepping"] = to_string(s.time.stepping);
  j["time"] = t;

  if (!s.probes.empty()) {
    j["probes"] = Json::array();
    for (const auto& p : s.probes) {
      Json o{{"type", to_string(p.kind)}, {"name", p.name}};
      if (p.kind == ProbeKind::water_height || p.kind == ProbeKind::surface_elevation) {
        o["x"] = p.x;
        if (p.band) o["band"] = *p.band;
      }
      if (p.kind == ProbeKind::surface_elevation) o["datum"] = p.datum;
      if (p.kind == ProbeKind::surge_front && p.origin) o["origin"] = *p.origin;
      if (p.kind == ProbeKind::pressure) o["position"] = vec(p.position);
      j["probes"].push_back(o);
    }
  }
  Json o;
  if (!s.output.folder.empty()) o["folder"] = s.output.folder;
  o["frames"] = s.output.frames;
  if (s.output.frame_interval) o["frame_interval"] = *s.output.frame_interval;
  if (!s.output.fields.empty()) o["fields"] = s.output.fields;
  j["output"] = o;
  return j;
}

}  // namespace sph::scene

#pragma once
// Programmatic set-up of the paper's cases and of simple test scenes (PHYSICS.md, "The paper's cases").
// Each builder returns a ready Simulation (rates evaluated, dt set).
#include <memory>
#include <optional>

#include "core/refinement/refinement_stage.hpp"
#include "core/simulation.hpp"

namespace sph {

struct TankSpec {
  double width = 25.0;
  double depth = 10.0;
  double spacing = 25.0 / 30.0;
  double h_factor = 1.2;
  double mach_factor = 10.0;
  // c0 = mach_factor sqrt(2 g H) (sound_speed_from_height). H = depth / 2: the floor's hydrostatic compression
  // g depth / c0^2 is then 1 / mach_factor^2, the 1 % the Mach rule aims at (c0 = 99 m/s, as cases/still_tank.json).
  double reference_height = 5.0;
  bool lennard_jones = false;
  GhostPressure ghost_pressure = GhostPressure::hydrostatic;
  bool density_diffusion = false;  // delta-SPH (delta = 0.1) with the hydrostatic correction
  TimeStepping stepping = TimeStepping::global;  // SolverSettings::stepping
};

/// Still water in a 3D box tank (open top, hydrostatic start, free-slip ghost walls on the floor and four sides).
struct Tank3Spec {
  double length = 1.0;  // x
  double width = 0.4;   // y
  double depth = 0.5;   // water depth, z; the walls reach twice as high
  double spacing = 0.05;
  double h_factor = 1.2;
  double mach_factor = 10.0;
  // c0 = mach_factor sqrt(2 g H), H = depth / 2, as for the 2D tank: the floor's compression is 1 / mach_factor^2.
  double reference_height = 0.25;
  GhostPressure ghost_pressure = GhostPressure::hydrostatic;
};

struct DamBreakSpec {
  double column_width = 25.0;
  double column_height = 25.0;
  double tank_width = 50.0;   // the obstacle at x = 50 m is the container's right wall
  double tank_height = 80.0;  // walls reach this high (open top): the jet up the right wall reaches ~50 m
  double spacing = 25.0 / 30.0;
  double h_factor = 1.2;
  double mach_factor = 10.0;  // c0 = mach_factor sqrt(2 g H0), H0 = column_height (sound_speed_from_height)
  int initial_level = 0;      // lattice built directly at spacing / 2^initial_level
  bool fully_refined = false; // static AAP refinement of every particle at set-up (the paper's 3600)
  std::optional<refine::RefinementSettings> refinement;  // dynamic refinement
  bool lennard_jones = true;
  bool ghosts = true;
  bool viscosity = true;
};

/// DualSPHysics' 3D dam break (its example CaseDambreak): a block of water at the start of a box tank, a square
/// column standing in its path. Ghost walls (free-slip) and Lennard-Jones wall particles at half the spacing.
struct DamBreak3Spec {
  Vec<3> tank = Vec<3>(1.6, 0.67, 0.4);
  Vec<3> water = Vec<3>(0.4, 0.67, 0.3);  // from the origin corner
  Vec<3> column_lo = Vec<3>(0.9, 0.24, 0.0);
  Vec<3> column_hi = Vec<3>(1.02, 0.36, 0.45);
  double spacing = 0.0085;
  double h_factor = 1.7320508075688772;  // sqrt(3), its coefh = 1
  double coef_sound = 20.0;              // c0 = coef_sound sqrt(g H), H the water's height
  double alpha = 0.02;
  bool density_diffusion = true;         // delta = 0.1
};

struct DropSpec {
  double width = 25.0;  // container x in [-width/2, width/2]
  double depth = 10.0;
  double radius = 2.0;
  Vec<2> centre = Vec<2>(0.0, 13.3);
  double drop_speed = 2.0;
  double spacing = 25.0 / 30.0;
  double h_factor = 1.2;
  double mach_factor = 10.0;
  // c0 = mach_factor sqrt(2 g H) (sound_speed_from_height). H = depth / 2, as for the still tank: the pool's
  // hydrostatic compression is 1 / mach_factor^2; c0 = 99 m/s (as cases/drop.json) is 18 times the drop's
  // impact speed, 5.4 m/s.
  double reference_height = 5.0;
  double alpha = 0.05;            // artificial viscosity (cases/drop.json says why not the default 0.02)
  bool density_diffusion = true;  // delta-SPH, delta = 0.1 (cases/drop.json says why)
  int initial_level = 0;
  bool fully_refined = false;
  std::optional<refine::RefinementSettings> refinement;
  bool lennard_jones = true;
};

/// Still water in a closed-sided open tank (hydrostatic start), ghost walls (free-slip).
Simulation make_still_tank(const TankSpec& spec);
/// The 3D still tank.
SimulationT<3> make_still_tank(const Tank3Spec& spec);
/// The paper's breaking dam: square column against the left wall, gravity, free-slip walls.
Simulation make_dam_break(const DamBreakSpec& spec);
/// DualSPHysics' 3D dam break.
SimulationT<3> make_dam_break(const DamBreak3Spec& spec);
/// The paper's splash of a drop into a pool.
Simulation make_drop(const DropSpec& spec);

}  // namespace sph

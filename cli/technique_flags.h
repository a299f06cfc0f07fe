// Each technique's flags, in an option group of its own with one prefix (--maps-*, --sh-*,
// --hierarchical-*, --fur-*, --reference-*), filling render::TechniqueOptions as CLI11 parses
// them: numbers through lucent's validators, enums from their names. The spellings of earlier
// releases (--frames, --hbe-mode, --samples-pixel, ...) stay for this release as hidden aliases;
// using one prints one deprecation line before the command runs (warn_deprecated_flags).
#pragma once

#include <CLI/CLI.hpp>

#include "lucent/render/frame_budget.h"
#include "lucent/render/technique.h"

namespace lucent::cli {

/// Adds the five groups to `cmd`, writing into `options` (whose values are the defaults shown).
void add_technique_flags(CLI::App* cmd, render::TechniqueOptions& options);

/// The radiance maps' sampling and sizes alone (--maps-directions, --maps-samples,
/// --maps-disc-points, --maps-radiance-map, --maps-light-map, with their earlier spellings), for
/// commands that time the maps (`bench render`).
void add_maps_sampling_flags(CLI::App* cmd, render::RenderSettings& settings);

/// The maps' knobs given on `cmd`'s command line under either spelling (they win over a budget).
render::FixedKnobs given_maps_knobs(const CLI::App* cmd);
/// Whether the reference's samples (per pixel, on the surface) or passes were given; the path
/// tracer's samples per pixel or passes.
bool given_reference_samples(const CLI::App* cmd);
bool given_pathtrace_samples(const CLI::App* cmd);

/// One line on stderr naming the deprecated spellings `cmd` was given and their new names; nothing
/// when none was used.
void warn_deprecated_flags(const CLI::App* cmd);

}  // namespace lucent::cli

// Each technique's flags as an option group (technique_flags.h).
#include "technique_flags.h"

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "validators.h"

namespace lucent::cli {
namespace {

// The earlier spellings: each writes where its new name writes. Kept out of the help by the
// formatter below (CLI11's own hiding, the empty group, would also take their names out of its
// error messages).
const std::string kDeprecatedGroup = "deprecated spellings";

class HelpWithoutDeprecated : public CLI::Formatter {
 public:
  std::string make_group(std::string group, bool is_positional,
                         std::vector<const CLI::Option*> opts) const override {
    if (group == kDeprecatedGroup) return {};
    return CLI::Formatter::make_group(std::move(group), is_positional, std::move(opts));
  }
};

// The options `cmd` marked as deprecated aliases of the new names (option -> new name), per app.
std::vector<std::pair<const CLI::Option*, std::string>>& aliases() {
  static std::vector<std::pair<const CLI::Option*, std::string>> all;
  return all;
}

// NAME in the group `g`, and ALIAS (when not empty) hidden on the command, both into `target`.
// `check` (when given) validates both spellings.
template <class T>
CLI::Option* flag(CLI::App* cmd, CLI::App* g, const std::string& name, const std::string& alias,
                  T& target, const std::string& help,
                  const std::optional<CLI::Validator>& check = std::nullopt) {
  if (!alias.empty()) {
    CLI::Option* old =
        cmd->add_option(alias, target, "deprecated: " + name)->group(kDeprecatedGroup);
    if (check) old->transform(*check);  // transform: whole_in rewrites 1e5 to its digits
    aliases().emplace_back(old, name);
  }
  CLI::Option* option = g->add_option(name, target, help)->capture_default_str();
  if (check) option->transform(*check);
  return option;
}

// One of `names`, parsed into the enum (or bool) `target` as CLI11 reads it; the default shown is
// the name of `target`'s value. A name not in the list: "NAME: expected a, b or c, got 'x'".
template <class T>
CLI::Option* choice_option(CLI::App* app, const std::string& name, T& target,
                           const std::vector<std::pair<std::string, T>>& names,
                           const std::string& help) {
  std::string list, current;
  for (std::size_t i = 0; i < names.size(); ++i) {
    list += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i].first;
    if (names[i].second == target) current = names[i].first;
  }
  return app
      ->add_option_function<std::string>(
          name,
          [&target, names](const std::string& text) {
            for (const auto& [n, value] : names)
              if (n == text) target = value;
          },
          help)
      ->check(CLI::Validator(
          [names, list](std::string& text) -> std::string {
            for (const auto& entry : names)
              if (entry.first == text) return {};
            return "expected " + list + ", got '" + text + "'";
          },
          list, "choice"))
      ->default_str(current);
}

template <class T>
CLI::Option* choice(CLI::App* cmd, CLI::App* g, const std::string& name, const std::string& alias,
                    T& target, const std::vector<std::pair<std::string, T>>& names,
                    const std::string& help) {
  if (!alias.empty()) {
    const CLI::Option* old =
        choice_option(cmd, alias, target, names, "deprecated: " + name)->group(kDeprecatedGroup);
    aliases().emplace_back(old, name);
  }
  return choice_option(g, name, target, names, help);
}

// An enum's CLI names are the technique's own to_string (found by argument-dependent lookup), so
// the flag, the Options' to_string and the viewer script spell a value alike.
template <class Enum>
std::vector<std::pair<std::string, Enum>> named(std::initializer_list<Enum> values) {
  std::vector<std::pair<std::string, Enum>> names;
  for (const Enum value : values) names.emplace_back(to_string(value), value);
  return names;
}

const std::vector<std::pair<std::string, bool>> kOnOff = {{"on", true}, {"off", false}};

// K, N and M, and the maps' sizes W_s and W_l, into group `g` (shared with `bench render`).
void add_maps_sampling_flags(CLI::App* cmd, CLI::App* g, render::RenderSettings& s) {
  flag(cmd, g, "--maps-directions", "--directions", s.directions,
       "K, radiance-map directions (Halton points on the sphere)", whole_in(1, 256, "directions"));
  flag(cmd, g, "--maps-samples", "--samples", s.samples,
       "N, disc samples gathered per texel per frame (N <= M)", whole_in(1, 65536, "disc samples"));
  flag(cmd, g, "--maps-disc-points", "--disc-points", s.disc_points,
       "M, disc points (a quadrature of the disc around each texel)",
       whole_in(1, 1048576, "disc points"));
  flag(cmd, g, "--maps-radiance-map", "--radiance-map", s.radiance_map_size,
       "W_s, radiance-map size in texels", whole_in(8, 8192, "texels"));
  flag(cmd, g, "--maps-light-map", "--light-map", s.light_map_size, "W_l, light-map size in texels",
       whole_in(8, 8192, "texels"));
}

void add_maps_flags(CLI::App* cmd, render::RenderSettings& s, render::RadianceMapOptions& m) {
  using render::DiscDistribution;
  using render::DiscSelection;
  CLI::App* g = cmd->add_option_group("maps", "--technique maps: real-time radiance maps");
  flag(cmd, g, "--maps-frames", "--frames", s.frames, "T, frames accumulated",
       whole_in(1, 100000, "frames"));
  add_maps_sampling_flags(cmd, g, s);
  choice(
      cmd, g, "--maps-disc-distribution", "--disc-distribution", s.disc_distribution,
      named({DiscDistribution::kProfile, DiscDistribution::kExponential}),
      "profile (radii importance-sampled from the material's own profile, weights exact at "
      "any texel size) or exponential (Dal Corso 2014: e^(-sigma* r), sigma* = min sigma_tr / q)");
  flag(cmd, g, "--maps-q", "--q", s.q,
       "q, disc bias sigma* = min sigma_tr / q (q > 1 spreads the samples wider)",
       number_in(0, 1000, "", true));
  choice(cmd, g, "--maps-disc-selection", "--disc-selection", s.disc_selection,
         named({DiscSelection::kStrata, DiscSelection::kNearest}),
         "which N of the M points a frame gathers: strata (one of each of N radius strata, a new "
         "one every frame: converges to all M after M/N frames) or nearest (Dal Corso 2014: the "
         "N nearest, every frame; misses the far profile)");
  flag(cmd, g, "--maps-max-blur", "--max-blur", m.max_blur_level,
       "mip blur levels at the first frame, fewer as frames accumulate (0 = none; -1: none with "
       "the profile disc, 2 with the exponential one)");
  choice(cmd, g, "--maps-layer-weights", "", m.cos_weighted_layers,
         std::vector<std::pair<std::string, bool>>{{"cos", true}, {"equal", false}},
         "the final pass's mean over the layers that see a point: cos (by n . w_k, the layer's "
         "texel density there) or equal (Dal Corso 2014)");
}

void add_sh_flags(CLI::App* cmd, render::ShOptions& o) {
  using render::ShAttenuation;
  CLI::App* g = cmd->add_option_group("sh", "--technique sh: spherical-harmonics translucency");
  flag(cmd, g, "--sh-shadow-map", "--shadow-map", o.shadow_map_size,
       "the primary light's shadow map (and depth peel), texels per side");
  flag(cmd, g, "--sh-cube-map", "--cube-map", o.cube_map_size,
       "texels per face of the external cube map of the lit object");
  flag(cmd, g, "--sh-depth-blur", "--depth-blur", o.depth_blur_sigma_texels,
       "sigma of the Gaussian blur of the light's depth map, shadow-map texels (0: none)");
  choice(cmd, g, "--sh-fresnel", "", o.schlick, {{"exact", false}, {"schlick", true}},
         "F_t in the cube map: exact (unpolarised Fresnel) or schlick (the seed's)");
  choice(cmd, g, "--sh-attenuation", "", o.attenuation,
         named({ShAttenuation::kSeed, ShAttenuation::kNormalised, ShAttenuation::kSlab}),
         "the attenuation in the thickness: seed (eq. 12 as printed, guarded), normalised (eq. 12 "
         "scaled to R_tot at d = 0) or slab (eq. 12 integrated over the plane, scaled to R_tot at "
         "d = 0)");
}

void add_hierarchical_flags(CLI::App* cmd, render::hierarchical::Options& o) {
  using render::hierarchical::DipolePlacement;
  using render::hierarchical::Mode;
  using render::hierarchical::SegmentRule;
  CLI::App* g = cmd->add_option_group(
      "hierarchical", "--technique hierarchical: boundary elements on a face-cluster hierarchy");
  choice(cmd, g, "--hierarchical-irradiance-cache", "--hbe-irradiance-cache", o.irradiance_cache,
         kOnOff,
         "on: area lights' leaf irradiance from per-cluster projection maps (Jacob 1993) built "
         "once; off: 16 shadow rays per leaf every frame");
  choice(cmd, g, "--hierarchical-mode", "--hbe-mode", o.mode,
         named({Mode::kRender, Mode::kIncremental, Mode::kOnTheFly}),
         "render (links kept), incremental (links repaired within --hierarchical-budget per "
         "frame) or on-the-fly (no stored links)");
  flag(cmd, g, "--hierarchical-epsilon1", "--hbe-epsilon1", o.epsilon_1,
       "split the receiver when the emitter's solid angle seen from its children deviates by "
       "more than this, sr");
  flag(cmd, g, "--hierarchical-epsilon2", "--hbe-epsilon2", o.epsilon_2,
       "split the emitter when its solid angle exceeds this, sr");
  flag(cmd, g, "--hierarchical-near", "--hbe-near", o.near,
       "links above this solid angle (sr) use the semi-analytic form factor, the others one "
       "midpoint sample");
  flag(cmd, g, "--hierarchical-planarity", "--hbe-planarity", o.min_planarity,
       "near emitter clusters less planar than this A'/A are split");
  flag(cmd, g, "--hierarchical-edge-constant", "--hbe-edge-constant", o.form_factor.edge_constant,
       "split edge segments until L/r0 < c and L sigma_tr < c (seed: 0.4)");
  choice(cmd, g, "--hierarchical-rule", "--hbe-rule", o.form_factor.rule,
         named({SegmentRule::kSeedMidpoint, SegmentRule::kGauss2}),
         "per segment, midpoint (the seed's eq. 17) or gauss2 (two-point Gauss-Legendre)");
  choice(cmd, g, "--hierarchical-dipole", "--hbe-dipole", o.form_factor.placement,
         named({DipolePlacement::kChord, DipolePlacement::kSeed3d}),
         "chord (R_d of the chord distance, lucent's, as the reference) or seed (sources at x_o "
         "-/+ z n_o)");
  flag(cmd, g, "--hierarchical-budget", "--hbe-budget", o.budget,
       "incremental mode: link factors evaluated per frame");
  flag(cmd, g, "--hierarchical-threads", "", o.threads,
       "threads for the oracle and the links' factors (0: all; the same links for any number)",
       thread_count());
}

void add_fur_flags(CLI::App* cmd, render::fur::FurOptions& o) {
  using render::fur::CoverageRule;
  CLI::App* g = cmd->add_option_group(
      "fur", "--technique fur (Klotzli & Olano's shells) and the --fur-coat's hairs");
  flag(cmd, g, "--fur-texels", "", o.texels, "the tile's texels across (seed: 64)",
       whole_in(2, 4096, "fur texels"));
  flag(cmd, g, "--fur-shells", "", o.shells, "shells (seed: 32)", whole_in(1, 1024, "fur shells"));
  flag(cmd, g, "--fur-seed", "", o.seed, "the hair generator's seed")->transform(seed_value());
  choice(cmd, g, "--fur-coverage", "", o.coverage,
         named({CoverageRule::kExact, CoverageRule::kSeed}),
         "a hair's cross-section over the texels: exact (the disc's overlap with each texel) or "
         "seed (its chord and wedge approximations, eqs. 1-2: the wedge is 13-32% off once a "
         "disc leaves the texel corner)");
  flag(cmd, g, "--fur-tile-mm", "", o.tile_mm,
       "fur over a mesh: the tile's width, mm (its texels set the hair scale)");
  flag(cmd, g, "--fur-height-mm", "", o.height_mm, "fur over a mesh: the coat's height, mm");
}

void add_reference_flags(CLI::App* cmd, render::ReferenceOptions& o) {
  using render::ReferenceSampling;
  CLI::App* g = cmd->add_option_group("reference", "--technique reference: the CPU reference");
  choice(cmd, g, "--reference-sampling", "", o.sampling,
         named({ReferenceSampling::kProbes, ReferenceSampling::kArea}),
         "probes (points drawn from the profile around each pixel, found by probe rays; noise ~ "
         "1/sqrt(--reference-samples-pixel)) or area (--reference-samples uniform surface "
         "samples shared by all pixels)");
  flag(cmd, g, "--reference-samples-pixel", "--samples-pixel", o.pixel_samples,
       "probes: probes per pixel per pass", whole_in(1, 10000000, "probes per pixel"));
  flag(cmd, g, "--reference-samples", "--samples-reference", o.surface_samples,
       "area: surface samples per pass (uniform by area)",
       whole_in(1, 1000000000, "surface samples"));
  flag(cmd, g, "--reference-area-light-samples", "--area-light-samples", o.area_light_samples,
       "points on each area light (shadow rays) per surface point, stratified, with the "
       "analytic form factor as control variate",
       whole_in(1, 4096, "area light samples"));
  choice(cmd, g, "--reference-irradiance-cache", "--irradiance-cache", o.irradiance_cache, kOnOff,
         "probes: on: area lights' irradiance from per-cluster projection maps (Jacob 1993; "
         "bilinear between grid vertices evaluated once) instead of shadow rays at every hit");
  flag(cmd, g, "--reference-single-samples", "", o.single_samples,
       "collisions drawn on each pixel's refracted view ray per pass (the single-scattering term)",
       whole_in(1, 1000000, "collisions per pixel"));
  flag(cmd, g, "--reference-passes", "--passes", o.passes,
       "progressive passes, each with new samples (image = their mean)",
       whole_in(1, 1000000, "passes"));
  flag(cmd, g, "--reference-threads", "--threads", o.threads, "worker threads (0 = all)",
       thread_count());
}

void add_pathtrace_flags(CLI::App* cmd, render::PathTraceOptions& o) {
  CLI::App* g = cmd->add_option_group(
      "pathtrace", "--technique pathtrace: volumetric path tracing, the truth (CPU)");
  flag(cmd, g, "--pathtrace-samples-pixel", "", o.pixel_samples,
       "paths per pixel per pass and channel; noise ~ 1/sqrt(N) (the statistics give it)",
       whole_in(1, 10000000, "paths per pixel"));
  flag(cmd, g, "--pathtrace-passes", "", o.passes,
       "progressive passes, each with new paths (image = their mean)",
       whole_in(1, 1000000, "passes"));
  choice(cmd, g, "--pathtrace-jitter", "", o.jitter, kOnOff,
         "on: paths spread over each pixel (a box filter, edges anti-aliased); off: through its "
         "centre (as the other techniques sample)");
  flag(cmd, g, "--pathtrace-threads", "", o.threads, "worker threads (0 = all)", thread_count());
}

}  // namespace

void add_maps_sampling_flags(CLI::App* cmd, render::RenderSettings& settings) {
  add_maps_sampling_flags(
      cmd, cmd->add_option_group("maps", "the radiance maps' sampling and sizes"), settings);
}

void add_technique_flags(CLI::App* cmd, render::TechniqueOptions& options) {
  cmd->formatter(std::make_shared<HelpWithoutDeprecated>());
  add_maps_flags(cmd, options.settings, options.maps);
  add_sh_flags(cmd, options.sh);
  add_hierarchical_flags(cmd, options.hierarchical);
  add_fur_flags(cmd, options.fur);
  add_reference_flags(cmd, options.reference);
  add_pathtrace_flags(cmd, options.pathtrace);
}

void warn_deprecated_flags(const CLI::App* cmd) {
  std::string used;
  for (const auto& [option, name] : aliases()) {
    bool mine = false;
    for (const CLI::Option* o : cmd->get_options())
      if (o == option) mine = true;
    if (mine && option->count() > 0) {
      used += (used.empty() ? "" : ", ") + option->get_name(false, true) + " is now " + name;
    }
  }
  if (!used.empty()) {
    std::fprintf(stderr, "lucent: deprecated: %s (the old spellings go in the next release)\n",
                 used.c_str());
  }
}

namespace {
bool given(const CLI::App* cmd, std::initializer_list<const char*> names) {
  for (const char* n : names) {
    const CLI::Option* o = cmd->get_option_no_throw(n);
    if (o != nullptr && o->count() > 0) return true;
  }
  return false;
}
}  // namespace

render::FixedKnobs given_maps_knobs(const CLI::App* cmd) {
  render::FixedKnobs fixed;
  fixed.frames = given(cmd, {"--maps-frames", "--frames"});
  fixed.directions = given(cmd, {"--maps-directions", "--directions"});
  fixed.samples = given(cmd, {"--maps-samples", "--samples"});
  fixed.radiance_map = given(cmd, {"--maps-radiance-map", "--radiance-map"});
  fixed.light_map = given(cmd, {"--maps-light-map", "--light-map"});
  return fixed;
}

bool given_reference_samples(const CLI::App* cmd) {
  return given(cmd, {"--reference-samples-pixel", "--samples-pixel", "--reference-samples",
                     "--samples-reference", "--reference-passes", "--passes"});
}

bool given_pathtrace_samples(const CLI::App* cmd) {
  return given(cmd, {"--pathtrace-samples-pixel", "--pathtrace-passes"});
}

}  // namespace lucent::cli

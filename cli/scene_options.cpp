// The options `lucent render` and `lucent view` share (see scene_options.h).
#include "scene_options.h"

#include "validators.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "lucent/core/error.h"
#include "lucent/materials/material.h"
#include "lucent/materials/profile_table.h"
#include "lucent/render/environment.h"

namespace lucent::cli {
namespace {

std::vector<double> parse_numbers(const std::string& text, const std::string& option,
                                  std::size_t count, char separator, const std::string& expected) {
  std::vector<double> values;
  std::size_t start = 0;
  for (;;) {
    const std::size_t end = text.find(separator, start);
    const std::string field = text.substr(start, end == std::string::npos ? end : end - start);
    char* stop = nullptr;
    const double v = std::strtod(field.c_str(), &stop);
    if (field.empty() || *stop != '\0' || !std::isfinite(v)) {
      throw Error(option + ": expected " + expected + ", got '" + text + "'");
    }
    values.push_back(v);
    if (end == std::string::npos) break;
    start = end + 1;
  }
  if (values.size() != count)
    throw Error(option + ": expected " + expected + ", got '" + text + "'");
  return values;
}

struct EnvironmentArgument {
  std::string path;
  int lights = 16;
};

// FILE[:L]: the count is split off only when what follows the last ':' is all digits, so paths
// with colons still work.
EnvironmentArgument parse_environment_argument(const std::string& text) {
  EnvironmentArgument env{text, 16};
  const auto colon = text.rfind(':');
  if (colon != std::string::npos && colon + 1 < text.size()) {
    const std::string tail = text.substr(colon + 1);
    if (std::all_of(tail.begin(), tail.end(), [](unsigned char c) { return std::isdigit(c); })) {
      env.path = text.substr(0, colon);
      env.lights = tail.size() > 6 ? 1000000 : std::stoi(tail);
    }
  }
  if (env.path.empty()) throw Error("--env: expected FILE[:L], got '" + text + "'");
  if (env.lights < 1 || env.lights > 4096) {
    throw Error("--env: the number of lights L must be 1..4096, got '" + text + "'");
  }
  return env;
}

}  // namespace

void add_scene_options(CLI::App* cmd, SceneArguments& args_, const std::string& size_help) {
  SceneArguments* args = &args_;
  cmd->add_option("--material", args->material,
                  "bundled material name (e.g. marble) or path to a lucent-material JSON file")
      ->required();
  cmd->add_option("--mesh", args->mesh,
                  "sphere, bunny, dragon:1 (finest) .. dragon:4 (coarsest), or a .ply / .obj file")
      ->capture_default_str();
  cmd->add_option("--light", args->lights,
                  "directional:DX,DY,DZ:R,G,B (direction toward the light; R,G,B irradiance on a "
                  "surface facing it), point:X,Y,Z:R,G,B (position in mm from the mesh centre; "
                  "R,G,B intensity per sr) or rect:CX,CY,CZ:UX,UY,UZ:VX,VY,VZ:R,G,B (an area "
                  "light: centre and half-edge vectors in mm, R,G,B radiance, emitting toward U x "
                  "V); repeatable");
  cmd->add_option("--env", args->env,
                  "FILE[:L]: lat-long environment map (.exr or .hdr), shown as background and lit "
                  "by L importance-sampled directional lights (default L = 16)");
  std::string technique_help;
  const auto& all = render::techniques();
  for (std::size_t i = 0; i < all.size(); ++i)
    technique_help += (i == 0 ? "" : i + 1 == all.size() ? " or " : ", ") + all[i].help;
  cmd->add_option("--technique", args->technique, technique_help)->capture_default_str();
  cmd->add_option("--model", args->model,
                  "tabulated (exact to Monte Carlo transport), ddipole (directional dipole) or "
                  "dipole (standard dipole); default: the material's fitted model, else tabulated "
                  "where the transport table covers the material, else ddipole");
  cmd->add_option("--view", args->view,
                  "AZ,EL,DIST: camera azimuth about +y from +z (degrees), elevation (degrees), "
                  "distance from the centre in bounding-sphere radii; field of view 35 degrees")
      ->capture_default_str();
  cmd->add_option("--size", args->size, size_help)->capture_default_str();
  cmd->add_option("--object-size-mm", args->object_size_mm, "bounding-box diagonal of the mesh, mm")
      ->check(number_in(0, 1e6, "mm", true))
      ->capture_default_str();
  cmd->add_option("--exposure", args->exposure,
                  "linear scale before the tone curve (PNG only; EXR stays linear), or auto: the "
                  "95th percentile of the object's luminance to 2 (2/3 after the curve)")
      ->capture_default_str();
  cmd->add_option("--roughness", args->roughness,
                  "GGX width alpha of the surface's specular lobe for every light (0 = smooth: "
                  "no highlight from point or directional lights, only the environment's "
                  "mirror image)")
      ->check(number_in(0, 1, "(GGX alpha)"))
      ->capture_default_str();
  cmd->add_option("--specular", args->specular,
                  "on or off: the lights' specular lobe (off: the subsurface term alone, for "
                  "comparing techniques)")
      ->capture_default_str();
  cmd->add_option("--backdrop", args->backdrop,
                  "R,G,B: radiance of the background where there is no environment map "
                  "(default black)");
  cmd->add_option("--reference-sampling", args->reference_sampling,
                  "reference: probes (points drawn from the profile around each pixel, found by "
                  "probe rays; noise ~ 1/sqrt(--samples-pixel)) or area (--samples-reference "
                  "uniform surface samples shared by all pixels)")
      ->capture_default_str();
  cmd->add_option("--samples-pixel", args->reference.pixel_samples,
                  "reference (probes): probes per pixel per pass")
      ->check(whole_in(1, 10000000, "probes per pixel"))
      ->capture_default_str();
  cmd->add_option("--samples-reference", args->reference.surface_samples,
                  "reference (area): surface samples per pass (uniform by area)")
      ->check(whole_in(1, 1000000000, "surface samples"))
      ->capture_default_str();
  cmd->add_option("--area-light-samples", args->reference.area_light_samples,
                  "reference: points on each area light (shadow rays) per surface point, "
                  "stratified, with the analytic form factor as control variate")
      ->check(whole_in(1, 4096, "area light samples"))
      ->capture_default_str();
  cmd->add_option("--irradiance-cache", args->irradiance_cache,
                  "reference (probes): on: area lights' irradiance from per-cluster projection "
                  "maps (Jacob 1993; bilinear between grid vertices evaluated once) instead of "
                  "shadow rays at every hit")
      ->capture_default_str();
  cmd->add_option("--passes", args->reference.passes,
                  "reference: progressive passes, each with new samples (image = their mean)")
      ->check(whole_in(1, 1000000, "passes"))
      ->capture_default_str();
  cmd->add_option("--threads", args->reference.threads, "reference: worker threads (0 = all)")
      ->check(thread_count())
      ->capture_default_str();
  cmd->add_option("--seed", args->reference.seed,
                  "random seed (reference samples, environment-light placement)")
      ->check(seed_value())
      ->capture_default_str();
  cmd->add_option("--frames", args->settings.frames, "maps: T, frames accumulated")
      ->capture_default_str();
  cmd->add_option("--directions", args->settings.directions,
                  "maps: K, radiance-map directions (Halton points on the sphere)")
      ->capture_default_str();
  cmd->add_option("--samples", args->settings.samples,
                  "maps: N, disc samples gathered per texel per frame (N <= M)")
      ->capture_default_str();
  cmd->add_option("--disc-points", args->settings.disc_points,
                  "maps: M, disc points (a quadrature of the disc around each texel)")
      ->capture_default_str();
  cmd->add_option("--disc-distribution", args->disc_distribution,
                  "maps: profile (radii importance-sampled from the material's own profile, "
                  "weights exact at any texel size) or exponential (Dal Corso 2014: e^(-sigma* r), "
                  "sigma* = min sigma_tr / q)")
      ->capture_default_str();
  cmd->add_option("--q", args->settings.q,
                  "maps: q, disc bias sigma* = min sigma_tr / q (q > 1 spreads the samples wider)")
      ->capture_default_str();
  cmd->add_option("--disc-selection", args->disc_selection,
                  "maps: which N of the M points a frame gathers: strata (one of each of N radius "
                  "strata, a new one every frame: converges to all M after M/N frames) or nearest "
                  "(Dal Corso 2014: the N nearest, every frame; misses the far profile)")
      ->capture_default_str();
  cmd->add_option("--shadow-map", args->sh.shadow_map_size,
                  "sh: the primary light's shadow map (and depth peel), texels per side")
      ->capture_default_str();
  cmd->add_option("--cube-map", args->sh.cube_map_size,
                  "sh: texels per face of the external cube map of the lit object")
      ->capture_default_str();
  cmd->add_option("--depth-blur", args->sh.depth_blur_sigma_texels,
                  "sh: sigma of the Gaussian blur of the light's depth map, shadow-map texels (0: "
                  "none)")
      ->capture_default_str();
  cmd->add_option("--sh-fresnel", args->sh_fresnel,
                  "sh: F_t in the cube map: exact (unpolarised Fresnel) or schlick (the seed's)")
      ->capture_default_str();
  cmd->add_option("--sh-attenuation", args->sh_attenuation,
                  "sh: the attenuation in the thickness: seed (eq. 12 as printed, guarded), "
                  "normalised (eq. 12 scaled to R_tot at d = 0) or slab (eq. 12 integrated over "
                  "the plane, scaled to R_tot at d = 0)")
      ->capture_default_str();
  cmd->add_option("--fur-texels", args->fur.texels, "fur: the tile's texels across (seed: 64)")
      ->check(whole_in(2, 4096, "fur texels"))
      ->capture_default_str();
  cmd->add_option("--fur-shells", args->fur.shells, "fur: shells (seed: 32)")
      ->check(whole_in(1, 1024, "fur shells"))
      ->capture_default_str();
  cmd->add_option("--fur-seed", args->fur.seed, "fur: the hair generator's seed")
      ->capture_default_str();
  cmd->add_option("--fur-coverage", args->fur_coverage,
                  "fur: a hair's cross-section over the texels: exact (the disc's overlap with "
                  "each texel) or seed (its chord and wedge approximations, eqs. 1-2: the wedge "
                  "is 13-32% off once a disc leaves the texel corner)")
      ->capture_default_str();
  cmd->add_option(
         "--fur-coat", args->fur_coat,
         "on: a fur coat over the skin (an extension of Klotzli & Olano): its transmittance "
         "T(cos theta), from the --fur-* hairs, attenuates the light entering the skin "
         "(maps, hierarchical, reference)")
      ->capture_default_str();
  cmd->add_option("--fur-tile-mm", args->fur.tile_mm,
                  "fur over a mesh: the tile's width, mm (its texels set the hair scale)")
      ->capture_default_str();
  cmd->add_option("--fur-height-mm", args->fur.height_mm, "fur over a mesh: the coat's height, mm")
      ->capture_default_str();
  cmd->add_option("--hbe-irradiance-cache", args->hbe_irradiance_cache,
                  "hierarchical: on: area lights' leaf irradiance from per-cluster projection maps "
                  "(Jacob 1993) built once; off: 16 shadow rays per leaf every frame")
      ->capture_default_str();
  cmd->add_option("--hbe-mode", args->hbe_mode,
                  "hierarchical: render (links kept), incremental (links repaired within "
                  "--hbe-budget per frame) or on-the-fly (no stored links)")
      ->capture_default_str();
  cmd->add_option("--hbe-epsilon1", args->hbe.epsilon_1,
                  "hierarchical: split the receiver when the emitter's solid angle seen from its "
                  "children deviates by more than this, sr")
      ->capture_default_str();
  cmd->add_option("--hbe-epsilon2", args->hbe.epsilon_2,
                  "hierarchical: split the emitter when its solid angle exceeds this, sr")
      ->capture_default_str();
  cmd->add_option("--hbe-near", args->hbe.near,
                  "hierarchical: links above this solid angle (sr) use the semi-analytic form "
                  "factor, the others one midpoint sample")
      ->capture_default_str();
  cmd->add_option("--hbe-planarity", args->hbe.min_planarity,
                  "hierarchical: near emitter clusters less planar than this A'/A are split")
      ->capture_default_str();
  cmd->add_option("--hbe-edge-constant", args->hbe.form_factor.edge_constant,
                  "hierarchical: split edge segments until L/r0 < c and L sigma_tr < c (seed: 0.4)")
      ->capture_default_str();
  cmd->add_option("--hbe-rule", args->hbe_rule,
                  "hierarchical: per segment, midpoint (the seed's eq. 17) or gauss2 (two-point "
                  "Gauss-Legendre)")
      ->capture_default_str();
  cmd->add_option("--hbe-dipole", args->hbe_dipole,
                  "hierarchical: chord (R_d of the chord distance, lucent's, as the reference) or "
                  "seed (sources at x_o -/+ z n_o)")
      ->capture_default_str();
  cmd->add_option("--hbe-budget", args->hbe.budget,
                  "hierarchical, incremental: link factors evaluated per frame")
      ->capture_default_str();
  cmd->add_option("--max-blur", args->max_blur,
                  "maps: mip blur levels at the first frame, fewer as frames accumulate (0 = none; "
                  "-1: none with the profile disc, 2 with the exponential one)")
      ->capture_default_str();
  cmd->add_option("--radiance-map", args->settings.radiance_map_size,
                  "maps: W_s, radiance-map size in texels")
      ->capture_default_str();
  cmd->add_option("--light-map", args->settings.light_map_size,
                  "maps: W_l, light-map size in texels")
      ->capture_default_str();
}

SceneSetup build_scene(SceneArguments& args) {
  using namespace lucent::render;
  // Everything that needs no file first, so that typing errors fail before any loading.
  const auto size = parse_numbers(args.size, "--size", 2, 'x', "WxH in pixels, e.g. 256x256");
  if (size[0] < 1 || size[1] < 1 || size[0] > 16384 || size[1] > 16384 ||
      size[0] != std::floor(size[0]) || size[1] != std::floor(size[1])) {
    throw Error("--size: width and height must be whole numbers 1..16384, got '" + args.size + "'");
  }
  const auto view =
      parse_numbers(args.view, "--view", 3, ',', "AZ,EL,DIST (degrees, degrees, bounding radii)");
  if (!(view[2] > 0 && view[2] <= 1e4) || !(std::abs(view[0]) <= 3600) ||
      !(std::abs(view[1]) <= 90)) {
    throw Error("--view: expected AZ in [-3600, 3600] degrees, EL in [-90, 90] degrees and DIST "
                "in (0, 1e4] bounding radii, got '" + args.view + "'");
  }
  args.technique_id = render::parse_technique(args.technique);
  const render::TechniqueInfo& technique = render::technique_info(args.technique_id);
  args.hbe.mode = render::hbe::parse_mode(args.hbe_mode);
  args.hbe.form_factor.rule = render::hbe::parse_segment_rule(args.hbe_rule);
  args.hbe.form_factor.placement = render::hbe::parse_dipole_placement(args.hbe_dipole);
  args.hbe.validate();
  if (technique.models.size() == 1 && !args.model.empty() &&
      args.model != materials::to_string(technique.models.front())) {
    throw Error("--model: the " + technique.name + " technique " + technique.model_note +
                ", got '" + args.model + "'; use --model " +
                materials::to_string(technique.models.front()) + " or leave it out");
  }
  if (args.sh_fresnel != "exact" && args.sh_fresnel != "schlick") {
    throw Error("--sh-fresnel: expected exact or schlick, got '" + args.sh_fresnel + "'");
  }
  args.sh.schlick = args.sh_fresnel == "schlick";
  args.sh.attenuation = render::parse_sh_attenuation(args.sh_attenuation);
  args.sh.validate();
  if (!(args.object_size_mm > 0) || !std::isfinite(args.object_size_mm)) {
    throw Error("--object-size-mm: must be positive");
  }
  if (args.reference.surface_samples < 1) throw Error("--samples-reference: must be at least 1");
  if (args.reference.passes < 1) throw Error("--passes: must be at least 1");
  args.settings.disc_selection = parse_disc_selection(args.disc_selection);
  args.settings.disc_distribution = parse_disc_distribution(args.disc_distribution);
  if (args.reference_sampling == "probes") {
    args.reference.sampling = ReferenceSampling::kProbes;
  } else if (args.reference_sampling == "area") {
    args.reference.sampling = ReferenceSampling::kArea;
  } else {
    throw Error("--reference-sampling: expected probes or area, got '" + args.reference_sampling +
                "'");
  }
  if (args.reference.pixel_samples < 1) throw Error("--samples-pixel: must be at least 1");
  if (args.max_blur < -1 || args.max_blur > 8) throw Error("--max-blur: must be -1..8");
  args.settings.validate();
  if (args.exposure == "auto") {
    args.auto_exposure = true;
    args.settings.exposure = 1.0f;
  } else {
    const auto e = parse_numbers(args.exposure, "--exposure", 1, ',', "a positive number or auto");
    if (!(e[0] > 0 && e[0] <= 1e12))
      throw Error("--exposure: expected a scale in (0, 1e12] or auto, got '" + args.exposure + "'");
    args.auto_exposure = false;
    args.settings.exposure = float(e[0]);
  }
  if (!(args.roughness >= 0) || !(args.roughness <= 1)) {
    throw Error("--roughness: the GGX width must be 0..1, got " + std::to_string(args.roughness));
  }
  for (const auto& [name, value] : {std::pair{"--irradiance-cache", &args.irradiance_cache},
                                    std::pair{"--hbe-irradiance-cache", &args.hbe_irradiance_cache}}) {
    if (*value != "on" && *value != "off") {
      throw Error(std::string(name) + ": expected on or off, got '" + *value + "'");
    }
  }
  args.reference.irradiance_cache = args.irradiance_cache == "on";
  if (args.fur_coat != "on" && args.fur_coat != "off") {
    throw Error("--fur-coat: expected on or off, got '" + args.fur_coat + "'");
  }
  if (args.fur_coat == "on" && !technique.fur_coat) {
    // The fur technique is its own coat; the others take one over their skin.
    throw Error("--fur-coat: the " + technique.name +
                " technique's precomputed transfer has no fur "
                "coat; use " +
                render::technique_names([](const render::TechniqueInfo& t) {
                  return t.fur_coat && t.id != render::TechniqueId::kFur;
                }));
  }
  if (args.fur_coverage != "exact" && args.fur_coverage != "seed") {
    throw Error("--fur-coverage: expected exact or seed, got '" + args.fur_coverage + "'");
  }
  args.fur.coverage = args.fur_coverage == "seed" ? render::fur::CoverageRule::kSeed
                                                  : render::fur::CoverageRule::kExact;
  if (args.technique_id == render::TechniqueId::kFur || args.fur_coat == "on") {
    // Hair counts follow the tile's area (the seed's density at 64 x 64 texels).
    const double scale = double(args.fur.texels) * args.fur.texels / (64.0 * 64.0);
    args.fur.overcoat.hairs = int(std::lround(600 * scale));
    args.fur.undercoat.hairs = int(std::lround(2400 * scale));
    args.fur.validate();
  }
  args.hbe.irradiance_cache = args.hbe_irradiance_cache == "on";
  if (args.specular != "on" && args.specular != "off") {
    throw Error("--specular: expected on or off, got '" + args.specular + "'");
  }
  Vec3f backdrop = Vec3f::Zero();
  if (!args.backdrop.empty()) {
    const auto b = parse_numbers(args.backdrop, "--backdrop", 3, ',', "R,G,B radiance >= 0");
    if (b[0] < 0 || b[1] < 0 || b[2] < 0 || b[0] > 1e12 || b[1] > 1e12 || b[2] > 1e12) {
      throw Error("--backdrop: expected R,G,B radiance in [0, 1e12], got '" + args.backdrop + "'");
    }
    backdrop = Vec3f(float(b[0]), float(b[1]), float(b[2]));
  }
  std::vector<Light> lights;
  for (const auto& text : args.lights) lights.push_back(parse_light(text));
  std::optional<EnvironmentArgument> env;
  if (!args.env.empty()) env = parse_environment_argument(args.env);
  args.default_rig.clear();
  if (lights.empty() && !env) {
    // The default rig, turned with the camera's azimuth so that it lights the object alike from
    // every --view: a key light above the camera's left, a dim fill from its right and a rim light
    // from behind (where a translucent object glows).
    const double a = view[0] * std::numbers::pi / 180.0;
    const auto turned = [a](double x, double y, double z) {
      char text[96];
      std::snprintf(text, sizeof text, "%.3g,%.3g,%.3g", std::cos(a) * x + std::sin(a) * z, y,
                    -std::sin(a) * x + std::cos(a) * z);
      return std::string(text);
    };
    args.default_rig = {"directional:" + turned(-1, 1, 1) + ":1,1,1",
                        "directional:" + turned(1, 0.3, 0.5) + ":0.3,0.3,0.3",
                        "directional:" + turned(0.3, 0.6, -1) + ":0.6,0.6,0.6"};
    for (const auto& text : args.default_rig) lights.push_back(parse_light(text));
  }

  Scene scene;
  scene.material = materials::load_material(args.material);
  args.settings.model = !args.model.empty()
                            ? materials::parse_diffusion_model(args.model, "--model", true)
                            : materials::preferred_model(scene.material);
  if (technique.models.size() == 1) args.settings.model = technique.models.front();
  scene.mesh = load_mesh(args.mesh, args.object_size_mm);
  scene.lights = lights;
  if (env) {
    const EnvironmentMap map = load_environment(env->path);
    const auto env_lights = environment_lights(map, env->lights, args.reference.seed);
    if (env_lights.empty() && lights.empty()) {
      throw Error("--env: " + env->path + " is black everywhere: no light");
    }
    scene.lights.insert(scene.lights.end(), env_lights.begin(), env_lights.end());
    scene.environment = env->path;
  }
  scene.roughness = args.roughness;
  scene.specular = args.specular == "on";
  scene.backdrop = backdrop;
  if (args.fur_coat == "on") scene.fur_coat = render::fur::make_fur_coat(render::fur::over_mesh(args.fur));
  scene.camera = orbit_camera(scene.mesh, float(view[0]), float(view[1]), float(view[2]),
                              int(size[0]), int(size[1]));
  return SceneSetup{std::move(scene), float(view[0]), float(view[1]), float(view[2])};
}


}  // namespace lucent::cli

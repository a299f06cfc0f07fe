// The options `lucent render` and `lucent view` share (see scene_options.h).
#include "scene_options.h"

#include "technique_flags.h"
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
  if (env.path.empty()) throw Error("--env: expected FILE[:L] or NAME[:L], got '" + text + "'");
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
                  "FILE[:L] or NAME[:L]: lat-long environment map (.exr or .hdr), or one the data "
                  "package brings by name (studio, sunset, forest, city, ...: Poly Haven's CC0 "
                  "HDRIs; an unknown name lists them), shown as background and lit by L "
                  "importance-sampled directional lights (default L = 16)");
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
  cmd->add_option("--crease-angle", args->crease_angle_deg,
                  "a mesh file without normals: edges where faces meet at more than this angle "
                  "are hard (flat shading on each side: cubes, tiles, slabs); 180 smooths "
                  "everything. A file's own normals (OBJ vn, PLY nx ny nz) are always used")
      ->check(number_in(0, 180, "degrees"))
      ->capture_default_str();
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
  cmd->add_option("--single-scattering", args->single_scattering,
                  "auto, on or off: the single-scattering term (Jensen et al. 2001) beside the "
                  "BSSRDF's multiple scattering, in the techniques that have it (auto: where "
                  "they do: the reference, maps and hierarchical; the path tracer's transport "
                  "always holds it)")
      ->capture_default_str();
  cmd->add_option("--angular", args->angular,
                  "on or off: the multiple scattering's dependence on the angles of incidence and "
                  "exit beyond Fresnel (Chandrasekhar's H-function of the reduced albedo) for the "
                  "radial models (tabulated, dipole) in the reference, maps and hierarchical")
      ->capture_default_str();
  cmd->add_option("--geometry-factor", args->geometry_factor,
                  "on or off: the multiple scattering's dependence on the object's shape between "
                  "entry and exit (the dipole's flux through the exit surface relative to a "
                  "plane's: curved surfaces, thin parts lit from behind) for the radial models "
                  "(tabulated, dipole) in the reference, maps and hierarchical")
      ->capture_default_str();
  cmd->add_option("--backdrop", args->backdrop,
                  "R,G,B: radiance of the background where there is no environment map "
                  "(default black)");
  cmd->add_option("--ground", args->ground,
                  "off, on (albedo 0.5) or R,G,B albedo in [0, 1]: a Lambertian ground plane under "
                  "the object, lit by the point and directional lights and an environment's, "
                  "shadowed by the object (--technique maps, and the viewer's maps)")
      ->capture_default_str();
  cmd->add_option("--seed", args->options.reference.seed,
                  "random seed (reference samples, environment-light placement)")
      ->transform(seed_value())
      ->capture_default_str();
  cmd->add_option(
         "--fur-coat", args->fur_coat,
         "on: a fur coat over the skin (an extension of Klotzli & Olano): its transmittance "
         "T(cos theta), from the --fur-* hairs, attenuates the light entering the skin "
         "(maps, hierarchical, reference)")
      ->capture_default_str();
  add_technique_flags(cmd, args->options);
  args->on_valid = [cmd] { warn_deprecated_flags(cmd); };
}

namespace {

// --size and --view, checked: {width, height} and {azimuth, elevation, distance}.
struct CameraArguments {
  std::vector<double> size, view;
};

CameraArguments parse_camera(const SceneArguments& args) {
  // One number is a square, as `simulate --size` takes it (--size 128 was refused here).
  const bool square =
      !args.size.empty() && args.size.find_first_not_of("0123456789") == std::string::npos;
  const std::string text = square ? args.size + "x" + args.size : args.size;
  const auto size =
      parse_numbers(text, "--size", 2, 'x', "WxH in pixels, e.g. 256x256 (or 256 for a square)");
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
  return {size, view};
}

// Every option that needs no file, checked before anything is loaded; the fur's hair counts set
// from its tile.
void check_options(SceneArguments& args, const render::TechniqueInfo& technique) {
  using render::TechniqueOptions;
  TechniqueOptions& o = args.options;
  o.hierarchical.validate();
  if (technique.models.size() == 1 && !args.model.empty() &&
      args.model != materials::to_string(technique.models.front())) {
    throw Error("--model: the " + technique.name + " technique " + technique.model_note +
                ", got '" + args.model + "'; use --model " +
                materials::to_string(technique.models.front()) + " or leave it out");
  }
  o.sh.validate();
  if (!(args.object_size_mm > 0) || !std::isfinite(args.object_size_mm)) {
    throw Error("--object-size-mm: must be positive");
  }
  o.reference.validate();
  o.pathtrace.seed = o.reference.seed;  // one --seed for both CPU renderers
  o.pathtrace.validate();
  o.maps.validate();
  o.settings.validate();
  if (args.exposure == "auto") {
    args.auto_exposure = true;
    o.settings.exposure = 1.0f;
  } else {
    const auto e = parse_numbers(args.exposure, "--exposure", 1, ',', "a positive number or auto");
    if (!(e[0] > 0 && e[0] <= 1e12))
      throw Error("--exposure: expected a scale in (0, 1e12] or auto, got '" + args.exposure + "'");
    args.auto_exposure = false;
    o.settings.exposure = float(e[0]);
  }
  if (!(args.roughness >= 0) || !(args.roughness <= 1)) {
    throw Error("--roughness: the GGX width must be 0..1, got " + std::to_string(args.roughness));
  }
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
  if (args.technique_id == render::TechniqueId::kFur || args.fur_coat == "on") {
    // Hair counts follow the tile's area (the seed's density at 64 x 64 texels).
    const double scale = double(o.fur.texels) * o.fur.texels / (64.0 * 64.0);
    o.fur.overcoat.hairs = int(std::lround(600 * scale));
    o.fur.undercoat.hairs = int(std::lround(2400 * scale));
    o.fur.validate();
  }
  if (args.single_scattering != "auto" && args.single_scattering != "on" &&
      args.single_scattering != "off") {
    throw Error("--single-scattering: expected auto, on or off, got '" + args.single_scattering +
                "'");
  }
  if (args.angular != "on" && args.angular != "off") {
    throw Error("--angular: expected on or off, got '" + args.angular + "'");
  }
  if (args.geometry_factor != "on" && args.geometry_factor != "off") {
    throw Error("--geometry-factor: expected on or off, got '" + args.geometry_factor + "'");
  }
  if (args.single_scattering == "on" && !technique.single_scattering) {
    throw Error("--single-scattering: the " + technique.name +
                " technique has no single-scattering term yet; use --single-scattering off or auto");
  }
  if (args.single_scattering == "off" && technique.id == render::TechniqueId::kPathtrace) {
    throw Error("--single-scattering: the path tracer's transport always holds single "
                "scattering; leave the option out");
  }
  if (args.specular != "on" && args.specular != "off") {
    throw Error("--specular: expected on or off, got '" + args.specular + "'");
  }
}

std::optional<render::Vec3f> parse_ground(const SceneArguments& args) {
  if (args.ground == "off") return std::nullopt;
  render::Vec3f albedo(0.5f, 0.5f, 0.5f);
  if (args.ground != "on") {
    const auto a = parse_numbers(args.ground, "--ground", 3, ',', "off, on or R,G,B albedo");
    for (double v : a)
      if (!(v >= 0 && v <= 1))
        throw Error("--ground: expected off, on or R,G,B albedo in [0, 1], got '" + args.ground +
                    "'");
    albedo = render::Vec3f(float(a[0]), float(a[1]), float(a[2]));
  }
  if (args.technique_id != render::TechniqueId::kMaps)
    throw Error("--ground: drawn by the maps only (--technique maps), got --technique " +
                args.technique);
  return albedo;
}

render::Vec3f parse_backdrop(const SceneArguments& args) {
  using render::Vec3f;
  Vec3f backdrop = Vec3f::Zero();
  if (!args.backdrop.empty()) {
    const auto b = parse_numbers(args.backdrop, "--backdrop", 3, ',', "R,G,B radiance >= 0");
    if (b[0] < 0 || b[1] < 0 || b[2] < 0 || b[0] > 1e12 || b[1] > 1e12 || b[2] > 1e12) {
      throw Error("--backdrop: expected R,G,B radiance in [0, 1e12], got '" + args.backdrop + "'");
    }
    backdrop = Vec3f(float(b[0]), float(b[1]), float(b[2]));
  }
  return backdrop;
}

// --light (or, with neither --light nor --env, the default rig turned with the camera's azimuth),
// and --env parsed into `env` (its lights are drawn once the map is loaded).
std::vector<render::Light> parse_lights(SceneArguments& args, double azimuth_deg,
                                        std::optional<EnvironmentArgument>& env) {
  using render::Light;
  using render::parse_light;
  std::vector<Light> lights;
  for (const auto& text : args.lights) lights.push_back(parse_light(text));
  if (!args.env.empty()) env = parse_environment_argument(args.env);
  args.default_rig.clear();
  if (lights.empty() && !env) {
    // The default rig, turned with the camera's azimuth so that it lights the object alike from
    // every --view: a key light above the camera's left, a dim fill from its right and a rim light
    // from behind (where a translucent object glows).
    const double a = azimuth_deg * std::numbers::pi / 180.0;
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
  return lights;
}

}  // namespace

SceneSetup build_scene(SceneArguments& args) {
  using namespace lucent::render;
  // Everything that needs no file first, so that typing errors fail before any loading.
  const auto [size, view] = parse_camera(args);
  args.technique_id = render::parse_technique(args.technique);
  const render::TechniqueInfo& technique = render::technique_info(args.technique_id);
  check_options(args, technique);
  TechniqueOptions& o = args.options;
  const Vec3f backdrop = parse_backdrop(args);
  const std::optional<Vec3f> ground = parse_ground(args);
  std::optional<EnvironmentArgument> env;
  const std::vector<Light> lights = parse_lights(args, view[0], env);

  Scene scene;
  scene.material = materials::load_material(args.material);
  o.settings.model = !args.model.empty()
                         ? materials::parse_diffusion_model(args.model, "--model", true)
                         : materials::preferred_model(scene.material);
  if (technique.models.size() == 1) o.settings.model = technique.models.front();
  scene.mesh = load_mesh(args.mesh, args.object_size_mm, args.crease_angle_deg);
  scene.lights = lights;
  if (env) {
    env->path = resolve_environment(env->path).string();  // a bundled map's name: its file
    const EnvironmentMap map = load_environment(env->path);
    const auto env_lights = environment_lights(map, env->lights, o.reference.seed);
    if (env_lights.empty() && lights.empty()) {
      throw Error("--env: " + env->path + " is black everywhere: no light");
    }
    scene.lights.insert(scene.lights.end(), env_lights.begin(), env_lights.end());
    scene.environment_lights = int(env_lights.size());
    scene.environment = env->path;
  }
  scene.roughness = args.roughness;
  scene.specular = args.specular == "on";
  // Techniques without the term ignore it; the viewer's switch reaches those with it.
  scene.single_scattering = args.single_scattering != "off";
  scene.angular = args.angular == "on";
  scene.geometry_factor = args.geometry_factor == "on";
  scene.backdrop = backdrop;
  scene.ground = ground;
  if (args.fur_coat == "on")
    scene.fur_coat = render::fur::make_fur_coat(render::fur::over_mesh(o.fur));
  scene.camera = orbit_camera(scene.mesh, float(view[0]), float(view[1]), float(view[2]),
                              int(size[0]), int(size[1]));
  if (args.on_valid) args.on_valid();
  return SceneSetup{std::move(scene), float(view[0]), float(view[1]), float(view[2])};
}

}  // namespace lucent::cli

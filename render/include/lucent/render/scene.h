// What a frame shows: a mesh, a material, lights, a camera. Shared by every technique (the real-time
// radiance-map pipeline, the CPU reference) so that they render exactly the same scene.
// Lengths: the mesh is scaled so that its bounding-box diagonal is object_size_mm (mm); the camera
// distance is in bounding-sphere radii.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "lucent/materials/material.h"
#include "lucent/render/fur_coat.h"

namespace lucent::render {

using Vec3f = Eigen::Vector3f;

/// An indexed triangle mesh with per-vertex normals, in mm after scaling.
struct Mesh {
  std::vector<Vec3f> positions;           ///< mm
  std::vector<Vec3f> normals;             ///< unit, per vertex (area-weighted face normals if absent)
  std::vector<std::array<unsigned, 3>> triangles;
  std::string name;

  Vec3f bounds_min() const;
  Vec3f bounds_max() const;
  Vec3f centre() const;                  ///< of the bounding box
  float bounding_radius() const;         ///< of the bounding sphere around centre(), mm
  double surface_area() const;           ///< mm^2
};

enum class LightType { kDirectional, kPoint, kArea };

struct Light {
  LightType type = LightType::kDirectional;
  Vec3f direction{0, 0, 1};  ///< directional: unit, from the object toward the light
  Vec3f position{0, 0, 0};   ///< point: mm, in the mesh's (scaled) frame
  Vec3f radiance{1, 1, 1};   ///< directional: irradiance on a surface facing it (W/mm^2, relative);
                             ///< point: intensity (W/sr, relative); area: radiance (W/mm^2/sr)
  /// area: the emitting polygon, mm (convex, planar, 3..kMaxPolygonVertices vertices), emitting
  /// one-sided toward its winding normal (right-hand rule); the irradiance at an unoccluded point
  /// is pi L F (polygon_form_factor.h). Made by area_light / rect_light (area_light.h).
  std::vector<Vec3f> polygon;
};

/// Orthographic light map / perspective camera conventions are the techniques' business; this is the
/// viewer's camera: looking at `target` from `eye`, vertical field of view in degrees.
struct Camera {
  Vec3f eye{0, 0, 300};
  Vec3f target{0, 0, 0};
  Vec3f up{0, 1, 0};
  float fov_y_deg = 35;
  int width = 128, height = 128;  ///< pixels
};

/// `--view AZ,EL,DIST`: azimuth and elevation in degrees, distance in bounding-sphere radii, looking
/// at the mesh's centre.
Camera orbit_camera(const Mesh& mesh, float azimuth_deg, float elevation_deg, float distance_radii,
                    int width, int height);

struct Scene {
  Mesh mesh;
  materials::Material material;
  std::vector<Light> lights;
  Camera camera;
  /// Environment map shown as the background (linear RGB, lat-long), optional; its light enters
  /// through `lights` (importance-sampled directional lights).
  std::optional<std::filesystem::path> environment;
  /// How many of `lights` (the last ones) stand for the environment map; the path tracer lights
  /// with the map itself and skips them.
  int environment_lights = 0;
  /// The surface's specular lobe for every light (materials/specular.h): GGX width alpha; 0 = a
  /// smooth interface (no highlight from point or directional lights). `--roughness`.
  float roughness = 0.1f;
  bool specular = true;  ///< `--specular off` renders the subsurface term alone
  /// Add the single-scattering term (Jensen et al. 2001) beside the BSSRDF's multiple scattering,
  /// in the techniques that have one (technique.h: TechniqueInfo::single_scattering). The CLI's
  /// `--single-scattering` turns it on by default; a Scene made in code has the BSSRDF alone.
  bool single_scattering = false;
  /// Give the radial BSSRDFs' multiple scattering (tabulated, dipole) its dependence on the angles
  /// of incidence and exit (materials/angular.h: Chandrasekhar's H-function of the reduced albedo,
  /// one factor per side) in the reference, the maps and the hierarchical technique. The CLI's
  /// `--angular` turns it on by default; a Scene made in code has the radial BSSRDF alone.
  /// With it, the reference and the maps also lean the profile toward each oblique beam's
  /// refracted direction, at entry and (by reciprocity) exit (materials::oblique_skew) unless
  /// `oblique_skew` is off (for measuring its share; the CLI's `--angular` sets both).
  bool angular = false;
  bool oblique_skew = true;
  /// Give the radial BSSRDFs' multiple scattering its dependence on the object's shape between
  /// the entry and exit points (materials/geometry_factor.h: the dipole's flux through the exit
  /// surface, relative to a plane's: curvature, and thin parts lit from behind) in the reference,
  /// the maps and the hierarchical technique. The CLI's `--geometry-factor` turns it on by
  /// default; a Scene made in code has the planar profile alone.
  bool geometry_factor = false;
  Vec3f backdrop{0, 0, 0};  ///< radiance of the background where no environment map is given
  /// `--ground`: a Lambertian ground plane of this albedo (RGB in [0, 1]) under the object, lit by
  /// the point and directional lights (an environment's too) and shadowed by the object. The maps
  /// draw it (render and view); not part of the object (its pixels are outside the mask).
  std::optional<Vec3f> ground;
  /// A fur coat over the skin (fur_coat.h, an extension of Klotzli & Olano): the maps and the
  /// reference attenuate each light sample's transmitted irradiance by its T(n . w_i). `--fur-coat
  /// on`.
  std::optional<FurCoat> fur_coat;
};

/// Parses `directional:DX,DY,DZ:R,G,B`, `point:X,Y,Z:R,G,B` or
/// `rect:CX,CY,CZ:UX,UY,UZ:VX,VY,VZ:R,G,B` (centre and half-edge vectors in mm, radiance; emits
/// toward U x V); throws lucent::Error naming --light.
Light parse_light(const std::string& text);

/// Built-in meshes and files: "sphere" (an icosphere of 5120 triangles; "sphere:L" has 20 x 4^L,
/// L 0..7), "bunny", "dragon:1".."dragon:4" (1 finest; from the npm data
/// cache, $LUCENT_DATA_CACHE or ~/.cache/lucent), or a path to a PLY or OBJ file. The mesh is
/// centred and scaled so that its bounding-box diagonal is `object_size_mm`. A file's normals (OBJ
/// `vn`, PLY nx ny nz) are used; a file without them gets hard edges where faces meet at more
/// than `crease_angle_deg` (kDefaultCreaseAngleDeg; 180: smooth everywhere), the built-in scans
/// smooth normals. Empty meshes throw; non-manifold ones load with a warning on stderr. "NAME@T"
/// (any of these, T a whole number) is that mesh simplified to about T triangles (simplify_mesh),
/// e.g. "bunny@2016", the seed 004's sizes; a file whose name has an '@' is read as a file.
inline constexpr double kDefaultCreaseAngleDeg = 60;
Mesh load_mesh(const std::string& name_or_path, double object_size_mm = 100.0,
               double crease_angle_deg = kDefaultCreaseAngleDeg);

/// The data cache scripts/install-deps fills (meshes, environment maps): $LUCENT_DATA_CACHE, else
/// $XDG_CACHE_HOME/lucent, else ~/.cache/lucent.
std::filesystem::path data_cache_dir();

/// Area-weighted vertex normals: the normalised sum of the (unnormalised) face cross products around
/// each vertex; +z where the sum vanishes. load_mesh uses them where a file has no normals, and a
/// deforming mesh recomputes them every frame.
std::vector<Vec3f> area_weighted_normals(const Mesh& mesh);

}  // namespace lucent::render

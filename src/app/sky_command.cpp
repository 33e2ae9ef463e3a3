// `lightcuts sky`: writes the sun_sky_light model (Preetham et al. 1999, scene/sky.h) as an
// equirectangular radiance map (.exr), in the scene units sun_sky_light uses (intensity 1: a
// white horizontal diffuse surface under sun and sky renders as 1). With --sun the sun's
// power goes into the pixel that holds its centre (a map that carries its own sun, like a
// captured HDR); without, the map is the sky alone. Used to make the test maps in data/.
#include <fmt/format.h>

#include <cmath>

#include "app/commands.h"
#include "core/error.h"
#include "core/file_util.h"
#include "io/image.h"
#include "scene/environment.h"

namespace lc::app {

namespace {

struct SkyArgs {
  std::string output;
  std::vector<float> direction{-0.4f, -0.6f, -0.7f};
  float turbidity = 3;
  std::vector<float> ground{0.2f, 0.2f, 0.2f};
  int width = 256, height = 128;
  bool sun = false;
};

int runSky(const SkyArgs& a) {
  if (fileExtension(a.output) != "exr") throw Error("sky writes .exr maps, got " + quoteInput(a.output));
  io::EnvironmentDesc d;
  d.kind = io::EnvironmentKind::SunSky;
  d.sunDirection = Vec3(a.direction[0], a.direction[1], a.direction[2]);
  d.turbidity = a.turbidity;
  d.ground = Color(a.ground[0], a.ground[1], a.ground[2]);
  if (!(d.sunDirection.y < 0)) throw Error("--direction: the sun must be above the horizon (y < 0)");
  if (!(d.turbidity >= 2 && d.turbidity <= 10)) throw Error("--turbidity must be in [2, 10]");
  if (!(d.ground.x >= 0 && d.ground.y >= 0 && d.ground.z >= 0)) throw Error("--ground must be >= 0");
  scene::Environment env = scene::Environment::build(d);
  io::Image img(a.width, a.height);
  for (int j = 0; j < a.height; ++j)
    for (int i = 0; i < a.width; ++i) {
      Vec3 dir = env.direction((i + 0.5) / a.width, (j + 0.5) / a.height);
      // The sky without the sun's disk (a pixel centre almost never lands on it).
      img.at(i, j) = dot(dir, -env.sunTravel()) >= std::cos(scene::PreethamSky::kSunRadius)
                         ? env.radiance(dir) - env.sunIrradiance() / scene::PreethamSky::sunSolidAngle()
                         : env.radiance(dir);
    }
  if (a.sun) {
    double u, v;
    env.coordinates(-env.sunTravel(), u, v);
    int i = std::min(a.width - 1, int(u * a.width)), j = std::min(a.height - 1, int(v * a.height));
    double omega = 2 * kPi / a.width * (std::cos(kPi * j / a.height) - std::cos(kPi * (j + 1) / a.height));
    img.at(i, j) += env.sunIrradiance() / float(omega);
  }
  io::writeImage(a.output, img);
  fmt::print("wrote {} ({}x{}, turbidity {}, sun {})\n", a.output, a.width, a.height, a.turbidity,
             a.sun ? "in the map" : "left out");
  return 0;
}

}  // namespace

void addSkyCommand(CLI::App& app) {
  auto a = std::make_shared<SkyArgs>();
  CLI::App* c = app.add_subcommand("sky", "Write the sun_sky_light model (Preetham 1999) as an equirectangular .exr map");
  c->add_option("output", a->output, "Output map (.exr)")->required();
  c->add_option("--direction", a->direction, "Direction sunlight travels, x y z (y up, y < 0); default -0.4 -0.6 -0.7")
      ->expected(3);
  c->add_option("--turbidity", a->turbidity, "Atmospheric turbidity in [2, 10]; default 3");
  c->add_option("--ground", a->ground, "Radiance below the horizon, r g b; default 0.2 0.2 0.2")->expected(3);
  c->add_option("--width", a->width, "Map width; default 256")->check(CLI::Range(1, 16384));
  c->add_option("--height", a->height, "Map height; default 128")->check(CLI::Range(1, 8192));
  c->add_flag("--sun", a->sun, "Put the sun's power into the pixel at its centre");
  c->callback([a] {
    if (!parseOnly()) exitStatus() = runSky(*a);
  });
}

}  // namespace lc::app

// `make verify` (issue 16): the whole verification suite, as many random trials as fit in the
// given time (default 10,000 or 15 minutes), both engines; prints the figures per engine and
// per geometry and every failure; exits 1 when the truth was missed in a noise-free trial or a
// certificate was contradicted.
//   verify_localization [--trials N] [--minutes M] [--seed S] [--resolution N] [--map FILE.poly[:SCALE] ...]
//                       [--random-maps N] [--buildings N] [--rooms N] [--scale S] [--k MIN:MAX] [--fov DEG]
//                       [--threads J]
// --map (repeatable) verifies on those polygon maps (scaled about the origin by SCALE), --random-maps
// on N random star-shaped 70-gons (mean radius 2 m, radii 1 to 3 m), --buildings on N generated
// 12 x 9 m buildings (1.2 m corridors, 3 m rooms, 10 cm walls), --rooms on N furnished rooms (8 x 6 m
// rooms and round halls 10 m across with 20 boxes and pillars, turned by any angle), all drawn
// from the seed: maps no test was tuned on; --scale S (0.05 to 20) scales the generated ones about
// the origin. Without any of them, the three small built-in maps. --k draws the readings per trial
// from [MIN, MAX] (default 4:30, within [3, 100]) to hunt where a search is hardest (few readings);
// at the default the trials of a seed are those of earlier builds. --fov gives every reading a cone
// of that full field of view [deg] (0 to 180): the same poses, cone ranges. --threads J (1 to 64,
// default 1) runs each localization on J threads: the answers, and so the figures, are those of one.
#include "generated_maps.h"
#include "verification_checks.h"

#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/util/text_parsing.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <string>

namespace
{
using fdml_localization::core::Engine;
using fdml_localization::core::Localizer;
using fdml_localization::core::MapRayCaster;
namespace verification = fdml_localization::core::verification;

struct Args
{
  long trials = 10000;
  double minutes = 15.0;
  unsigned long seed = 16;
  int resolution = 64;
  int threads = 1;
  std::vector<std::string> maps;  ///< FILE.poly[:SCALE]; none of these three: verification::smallMaps()
  int random_maps = 0;
  int buildings = 0;
  int rooms = 0;
  double scale = 1.0;            ///< the generated maps scaled about the origin
  verification::TrialSpec spec;  ///< --k, --fov
};

/// Readings per trial (--k): at least as many as the localizer takes, at most this many.
constexpr int kMinK = 3;
constexpr int kMaxK = 100;

/// Parses --k's MIN:MAX into @p spec. @throws std::invalid_argument naming the flag.
void parseK(const std::string& text, verification::TrialSpec& spec)
{
  const std::size_t colon = text.find(':');
  if (colon == std::string::npos)
  {
    throw std::invalid_argument("--k: '" + text + "' is not MIN:MAX");
  }
  const int k_min = fdml_localization::core::parseInteger(text.substr(0, colon), "--k MIN");
  const int k_max = fdml_localization::core::parseInteger(text.substr(colon + 1), "--k MAX");
  if (k_min < kMinK || k_max < k_min || k_max > kMaxK)
  {
    throw std::invalid_argument("--k needs " + std::to_string(kMinK) + " <= MIN <= MAX <= " + std::to_string(kMaxK) +
                                ", got '" + text + "'");
  }
  spec.k_min = k_min;
  spec.k_max = k_max;
}

/// Parses --fov's DEG (the sensors' full field of view, [0, 180]) into @p spec.
/// @throws std::invalid_argument naming the flag.
void parseFov(const std::string& text, verification::TrialSpec& spec)
{
  const double degrees = fdml_localization::core::parseNumber(text, "--fov");
  if (!(degrees >= 0.0 && degrees <= 180.0))
  {
    throw std::invalid_argument("--fov needs a field of view in [0, 180] degrees (0 = rays), got '" + text + "'");
  }
  spec.half_angle = 0.5 * degrees * verification::kDeg;
}

/// parseK() or parseFov() as @p flag says; false (and a message) on a bad @p value.
bool parseTrialFlag(const char* flag, const std::string& value, verification::TrialSpec& spec)
{
  try
  {
    std::strcmp(flag, "--k") == 0 ? parseK(value, spec) : parseFov(value, spec);
  }
  catch (const std::invalid_argument& e)
  {
    std::cerr << "verify_localization: " << e.what() << "\n";
    return false;
  }
  return true;
}

/// Generated maps beside the files: at most this many of each kind ...
constexpr double kMaxGenerated = 100;
/// ... scaled by a factor in this range (--scale).
constexpr double kMinScale = 0.05;
constexpr double kMaxScale = 20.0;

/// Sets the numeric flag @p flag to @p value (positive, at most 1e9); false for an unknown flag
/// or a value outside the flag's range.
bool setNumericFlag(const char* flag, double value, Args& args)
{
  if (std::strcmp(flag, "--trials") == 0)
  {
    args.trials = static_cast<long>(value);
  }
  else if (std::strcmp(flag, "--minutes") == 0)
  {
    args.minutes = value;
  }
  else if (std::strcmp(flag, "--seed") == 0)
  {
    args.seed = static_cast<unsigned long>(value);
  }
  else if (std::strcmp(flag, "--resolution") == 0 && value >= 16 && value <= 1024)
  {
    args.resolution = static_cast<int>(value);
  }
  else if (std::strcmp(flag, "--threads") == 0 && value >= 1 && value <= 64)
  {
    args.threads = static_cast<int>(value);
  }
  else if (std::strcmp(flag, "--random-maps") == 0 && value <= kMaxGenerated)
  {
    args.random_maps = static_cast<int>(value);
  }
  else if (std::strcmp(flag, "--buildings") == 0 && value <= kMaxGenerated)
  {
    args.buildings = static_cast<int>(value);
  }
  else if (std::strcmp(flag, "--rooms") == 0 && value <= kMaxGenerated)
  {
    args.rooms = static_cast<int>(value);
  }
  else if (std::strcmp(flag, "--scale") == 0 && value >= kMinScale && value <= kMaxScale)
  {
    args.scale = value;
  }
  else
  {
    return false;
  }
  return true;
}

bool parse(int argc, char** argv, Args& args)
{
  for (int i = 1; i + 1 < argc; i += 2)
  {
    if (std::strcmp(argv[i], "--map") == 0)
    {
      args.maps.emplace_back(argv[i + 1]);
      continue;
    }
    if (std::strcmp(argv[i], "--k") == 0 || std::strcmp(argv[i], "--fov") == 0)
    {
      if (!parseTrialFlag(argv[i], argv[i + 1], args.spec))
      {
        return false;
      }
      continue;
    }
    char* end = nullptr;
    const double value = std::strtod(argv[i + 1], &end);
    if (end == argv[i + 1] || *end != '\0' || !(value > 0.0) || value > 1e9)
    {
      std::cerr << "verify_localization: " << argv[i] << " needs a positive number, got '" << argv[i + 1] << "'\n";
      return false;
    }
    if (!setNumericFlag(argv[i], value, args))
    {
      std::cerr << "verify_localization: unknown flag or value " << argv[i] << "\n";
      return false;
    }
  }
  return argc % 2 == 1;
}

void print(const char* name, const verification::Figures& f)
{
  std::printf("%-9s trials %6d  noise-free %6d  undetermined %5d  missed %d  inaccurate %d  contradicted %d  "
              "far optima %d  complete %5.1f %%  top-1 %5.1f %%  mean %.1f ms\n",
              name, f.trials, f.noise_free, f.undetermined, f.missed, f.inaccurate, f.contradicted, f.far_optima,
              f.trials ? 100.0 * f.complete / f.trials : 0.0, f.trials ? 100.0 * f.top1 / f.trials : 0.0,
              f.trials ? 1000.0 * f.seconds / f.trials : 0.0);
}

void add(const verification::Figures& one, verification::Figures& f)
{
  f.trials += one.trials;
  f.noise_free += one.noise_free;
  f.undetermined += one.undetermined;
  f.missed += one.missed;
  f.inaccurate += one.inaccurate;
  f.contradicted += one.contradicted;
  f.far_optima += one.far_optima;
  f.complete += one.complete;
  f.top1 += one.top1;
  f.seconds += one.seconds;
}
/// The map of one --map value, FILE.poly[:SCALE] (SCALE in (0, 1e6], about the origin).
fdml_localization::core::PolygonMap mapOf(const std::string& spec)
{
  const auto [path, scale] = fdml_localization::core::splitScale(spec, "--map " + spec);
  return fdml_localization::core::loadPolyFile(path).scaled(scale);
}

/// The maps of --map, --random-maps and --buildings, or without any the small built-in maps, with
/// their names; false (and a message) on a bad file or scale.
bool loadMaps(const Args& args, std::vector<std::shared_ptr<const MapRayCaster>>& maps, std::vector<std::string>& names)
{
  try
  {
    for (const std::string& spec : args.maps)
    {
      maps.push_back(std::make_shared<const MapRayCaster>(mapOf(spec)));
      names.push_back(spec);
    }
    for (verification::GeneratedMap& generated :
         verification::generatedMaps(args.random_maps, args.buildings, args.seed, args.rooms))
    {
      if (args.scale == 1.0)
      {
        maps.push_back(std::move(generated.map));
        names.push_back(std::move(generated.name));
        continue;
      }
      maps.push_back(std::make_shared<const MapRayCaster>(generated.map->map().scaled(args.scale)));
      char factor[32];
      std::snprintf(factor, sizeof(factor), " x %g", args.scale);
      names.push_back(generated.name + factor);
    }
  }
  catch (const std::exception& e)
  {
    std::cerr << "verify_localization: " << e.what() << "\n";
    return false;
  }
  if (maps.empty())
  {
    maps = verification::smallMaps();
    names = { "maps/l_room.poly", "L-room 8 x 6 m (lRoomMap())", "maps/square_room.poly" };
  }
  return true;
}
/// Prints the figures per engine and per geometry.
void report(const Args& args, const std::vector<std::string>& names, long trial_count, double seconds,
            const verification::Figures (&total)[2],
            const verification::Figures (&by_geometry)[2][verification::kGeometries])
{
  std::printf("\n%ld trials per engine in %.0f s (seed %lu, resolution %d, k %d to %d, field of view %g deg)\n",
              trial_count, seconds, args.seed, args.resolution, args.spec.k_min, args.spec.k_max,
              2.0 * args.spec.half_angle / verification::kDeg);
  for (std::size_t m = 0; m < names.size(); ++m)
  {
    std::printf("map %zu: %s\n", m, names[m].c_str());
  }
  for (int e = 0; e < 2; ++e)
  {
    print(e == 0 ? "voxel" : "adaptive", total[e]);
    for (int g = 0; g < verification::kGeometries; ++g)
    {
      print(verification::geometryName(g), by_geometry[e][g]);
    }
  }
}
}  // namespace

int main(int argc, char** argv)
{
  Args args;
  if (!parse(argc, argv, args))
  {
    std::cerr << "usage: verify_localization [--trials N] [--minutes M] [--seed S] [--resolution N] "
                 "[--map FILE.poly[:SCALE] ...] [--random-maps N] [--buildings N] [--rooms N] [--scale S] "
                 "[--k MIN:MAX] [--fov DEG] [--threads J]\n";
    return 2;
  }
  std::vector<std::shared_ptr<const MapRayCaster>> maps;
  std::vector<std::string> names;
  if (!loadMaps(args, maps, names))
  {
    return 2;
  }
  const std::vector<std::unique_ptr<Localizer>> localizers[2] = {
    verification::localizersFor(maps, Engine::Voxel, args.resolution, args.threads),
    verification::localizersFor(maps, Engine::Adaptive, args.resolution, args.threads)
  };
  std::mt19937_64 rng(args.seed);
  verification::Figures total[2];
  verification::Figures by_geometry[2][verification::kGeometries];
  const auto start = std::chrono::steady_clock::now();
  long trial_count = 0;
  for (; trial_count < args.trials; ++trial_count)
  {
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > 60.0 * args.minutes)
    {
      break;
    }
    const verification::Trial trial = verification::makeTrial(maps, rng, args.spec);
    for (int e = 0; e < 2; ++e)
    {
      verification::Figures one;
      verification::runTrial(*localizers[e][static_cast<std::size_t>(trial.map)], trial, 300, rng, one);
      add(one, total[e]);
      add(one, by_geometry[e][trial.geometry]);
      for (const std::string& failure : one.failures)
      {
        std::printf("FAIL %s: %s\n", e == 0 ? "voxel" : "adaptive", failure.c_str());
      }
    }
  }
  report(args, names, trial_count, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
         total, by_geometry);
  const bool ok = total[0].missed + total[1].missed + total[0].contradicted + total[1].contradicted == 0;
  return ok ? 0 : 1;
}

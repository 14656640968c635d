// bench_gpu_fog.cpp — see bench_gpu_fog.h.
#include "app/bench/bench_gpu_fog.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <variant>

#include <unistd.h>

#include "app/bench/bench_metrics.h"
#include "app/bench/bench_rows.h"
#include "app/bench/fog_view.h"
#include "app/bench/plot.h"
#include "app/front/args.h"
#include "app/front/render_input.h"
#include "core/cpu/photons.h"
#include "core/cpu/render_cpu.h"
#include "core/cpu/sun_maps.h"
#include "core/gl/render_gl.h"
#include "core/util/parallel.h"

namespace sylva::cli {

namespace {

struct FogMethod {
  std::string name;  // "brute 64", "fast", "medium 64", "map 2048²"
  FogMode mode;
  uint32_t steps;
  uint32_t map_resolution = 0;  // map: texels a side
};

std::vector<FogMethod> fog_methods(bool quick, uint32_t medium_steps, uint32_t map_resolution) {
  std::vector<FogMethod> m;
  for (uint32_t n : quick ? std::vector<uint32_t>{16, 64} : std::vector<uint32_t>{16, 32, 64, 128, 256})
    m.push_back({"brute " + std::to_string(n), FogMode::brute, n});
  m.push_back({"fast", FogMode::fast, medium_steps});
  m.push_back({"medium " + std::to_string(medium_steps), FogMode::medium, medium_steps});
  // map at the scene's resolution, and (not --quick) coarser: its error against its cost.
  std::vector<uint32_t> sides = {map_resolution};
  if (!quick)
    for (uint32_t side : {512u, 1024u, 4096u})
      if (side != map_resolution) sides.push_back(side);
  std::sort(sides.begin(), sides.end());
  for (uint32_t side : sides)
    m.push_back({"map " + std::to_string(side) + "\u00b2", FogMode::map, medium_steps, side});
  return m;
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The in-scatter's (fog.R fog.G fog.B) RMSE of `test` against the reference (RGB at
// `pixels`, fog_view.h), and both means over those pixels.
struct FogError {
  double rmse = 0, mean_ref = 0, mean_test = 0;
};
FogError fog_error(const RenderImage& test, const std::vector<double>& reference, const std::vector<size_t>& pixels) {
  if (pixels.empty() || test.fog.size() < (pixels.back() + 1) * 4) return {std::nan(""), std::nan(""), std::nan("")};
  FogError e;
  e.rmse = rmse_at(test.fog, 4, reference, pixels);
  for (size_t k = 0; k < pixels.size(); ++k)
    for (int c = 0; c < 3; ++c) e.mean_ref += reference[k * 3 + c], e.mean_test += test.fog[pixels[k] * 4 + c];
  e.mean_ref /= 3.0 * pixels.size();
  e.mean_test /= 3.0 * pixels.size();
  return e;
}

std::string number(double v) {
  if (std::isnan(v)) return "";
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

std::string quoted(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string q = "\"";
  for (char c : text) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

const char* const kGpuFogCsvColumns =
    "device,gl_renderer,input,width,height,method,mode,steps,status,reason,frames,fog_ms_median,cones_ms_median,"
    "frame_gpu_ms_median,cones,photons,overflow_pixels,fog_rmse,fog_rmse_relative,fog_bias_relative,reference\n";

int run_gpu_fog_rows(const GpuFogArgs& a, const std::string& device, const GlContextInfo& gl) {
  // Each row as it finishes, with a progress line (bench_rows.h): a long run stopped
  // early keeps what it measured.
  const size_t planned = a.inputs.size() * a.sizes.size() * fog_methods(a.quick, 1, Fog{}.map_resolution).size();
  BenchRows csv("sylva bench gpu --fog", a.csv,
                "# sylva bench gpu --fog on " + device + " (" + gl.describe() + "), " + std::to_string(a.frames) +
                    " frames after " + std::to_string(a.warmup) + " warm-up frames, sun as a point\n" +
                    kGpuFogCsvColumns,
                planned, isatty(STDERR_FILENO) != 0);
  if (Status e = csv.start(); !e) {
    std::cerr << e.error().format();
    return kInputError;
  }
  std::printf("%-34s %-11s %10s %10s %10s %8s %10s %9s\n", "input", "method", "fog_ms", "cones_ms", "frame_ms", "cones",
              "rmse_rel", "bias_rel");
  const unsigned threads = worker_count(0);
  std::vector<PlotPanel> panels;
  int failed = 0;
  for (const std::string& input : a.inputs) {
    for (const auto& [width, height] : a.sizes) {
      std::vector<RenderPass> passes;
      GrammarArgs grammar;
      grammar.grammar = input;
      auto loaded = load_render_input(grammar, width, height, passes);
      if (auto* code = std::get_if<ExitCode>(&loaded)) return *code;
      Scene scene = std::move(std::get<Scene>(loaded));
      if (!scene.fog) {
        std::cerr << "sylva bench gpu --fog: " << input << " has no fog\n";
        return kInputError;
      }
      scene.sun.angular_radius_deg = 0;  // one GL sample sees the disc's centre: a point sun on both
      const uint64_t photons = a.quick ? std::min<uint64_t>(scene.fog->photons, 200000) : scene.fog->photons;
      const std::string where = input.substr(input.find_last_of('/') + 1) + " " + std::to_string(width) + "x" +
                                std::to_string(height);
      std::cerr << "sylva bench gpu --fog: CPU reference fog of " << where << ", every " << a.reference_stride
                << "-th pixel each way, " << threads << " threads\n";
      // The reference: render_cpu's fog AOV (mode reference at the scene's steps) through
      // the pixel centres of a uniform grid of the image (fog_view.h).
      GeometryOptions geometry_options;
      geometry_options.cull = false;  // a plant outside the view still casts shafts into it
      const SceneGeometry geometry = build_scene_geometry(scene, SkinOptions{}, geometry_options);
      std::vector<double> reference;
      std::vector<size_t> pixels;
      double reference_s = 0;
      {
        FogIntegratorOptions ro;
        ro.mode = FogMode::reference;
        ro.steps = scene.fog->steps;
        const FogIntegrator integrator(fog_medium_of(scene), fog_sun_of(scene.sun), scene.sky, *geometry.tracer,
                                       nullptr, ro);
        const View sparse = strided(pixel_rays(scene, *geometry.tracer), a.reference_stride, &pixels);
        const std::vector<float> image = fog_image(sparse, integrator, 0, threads, &reference_s);
        reference.assign(image.begin(), image.end());
      }
      std::cerr << "sylva bench gpu --fog: reference of " << pixels.size() << " pixels in " << reference_s << " s\n";
      std::unique_ptr<const SunCones> cones[2];  // fast's, medium's (the automatic choice weighs misses apart)
      std::map<uint32_t, SunMaps> maps;           // map's by resolution, built once on the CPU (its cost: stderr)
      PlotPanel panel{where + ", " + device, "fog GPU time per frame (ms)", "fog RMSE / mean", {}};
      for (const FogMethod& m : fog_methods(a.quick, scene.fog->steps, scene.fog->map_resolution)) {
        Scene s = scene;
        s.fog->mode = m.mode;
        s.fog->steps = m.steps;
        RenderOptions options;
        options.aovs = kAovFog;
        std::string status = "ok", reason;
        std::vector<double> fog_ms, cones_ms, frame_ms;
        size_t cone_count = 0;
        uint64_t overflow = 0;
        FogError e{std::nan(""), std::nan(""), std::nan("")};
        try {
          GlRenderer renderer(s, options);
          if (m.mode == FogMode::map) {
            auto found = maps.find(m.map_resolution);
            if (found == maps.end()) {
              SunMapOptions mo;
              mo.resolution = m.map_resolution;
              mo.disc_maps = s.fog->map_directions;
              mo.threads = threads;
              Expected<SunMaps> built = build_sun_maps_of(geometry, s, std::min(photons, kSunMapTilePhotons), mo, nullptr);
              if (!built) throw std::runtime_error(built.error().message);
              found = maps.emplace(m.map_resolution, std::move(*built)).first;
              std::cerr << "sylva bench gpu --fog: sun maps of " << where << ": " << found->second.describe() << " in "
                        << found->second.seconds << " s on the CPU\n";
            }
            renderer.set_fog_maps(found->second.maps);
          } else if (m.mode != FogMode::brute) {
            std::unique_ptr<const SunCones>& c = cones[m.mode == FogMode::medium ? 1 : 0];
            if (!c) c = build_sun_cones(geometry, s, sun_cone_options_for(m.mode, photons, std::nullopt, threads, nullptr));
            renderer.set_fog_cones(c->cones);
            cone_count = c->cones.size();
          }
          RenderImage image;
          for (uint32_t f = 0; f < a.warmup + a.frames; ++f) {
            renderer.draw(s);
            const GlFrameStats stats = renderer.wait_for_frame();
            image = renderer.read_back();
            if (f < a.warmup) continue;
            fog_ms.push_back(stats.pass(GlPass::fog).gpu_s * 1e3);
            cones_ms.push_back(stats.pass(GlPass::fog_cones).gpu_s * 1e3);
            frame_ms.push_back(stats.gpu_s() * 1e3);
            overflow = stats.fog_overflow_pixels;
          }
          e = fog_error(image, reference, pixels);
        } catch (const std::exception& ex) {
          status = "failed";
          reason = ex.what();
          ++failed;
        }
        const double rel = e.rmse / e.mean_ref, bias = (e.mean_test - e.mean_ref) / e.mean_ref;
        std::ostringstream line;
        line << quoted(device) << ',' << quoted(gl.renderer) << ',' << quoted(input) << ',' << width << ',' << height
            << ',' << quoted(m.name) << ',' << fog_mode_name(m.mode) << ',' << m.steps << ',' << status << ','
            << quoted(reason) << ',' << fog_ms.size() << ',' << number(median(fog_ms)) << ','
            << number(median(cones_ms)) << ',' << number(median(frame_ms)) << ',' << cone_count << ','
            << (m.mode == FogMode::brute ? 0 : photons) << ',' << overflow << ',' << number(e.rmse) << ','
            << number(rel) << ',' << number(bias) << ",CPU fog reference"
            << (a.reference_stride > 1 ? " on every " + std::to_string(a.reference_stride) + "-th pixel each way" : "")
            << "\n";
        if (Status written = csv.add(line.str(), where + " " + m.name); !written) {
          std::cerr << written.error().format();
          return kInputError;
        }
        if (status != "ok") {
          std::printf("%-34s %-11s failed: %s\n", where.c_str(), m.name.c_str(), reason.c_str());
        } else {
          std::printf("%-34s %-11s %10.3f %10.3f %10.3f %8zu %10.4f %+9.4f\n", where.c_str(), m.name.c_str(),
                      median(fog_ms), median(cones_ms), median(frame_ms), cone_count, rel, bias);
          series_named(panel.series, fog_mode_name(m.mode))
              .points.push_back({median(fog_ms) + median(cones_ms), rel});
        }
        std::fflush(stdout);
      }
      panels.push_back(std::move(panel));
    }
  }
  if (Status e = csv.finish(); !e) {
    std::cerr << e.error().format();
    return kInputError;
  }
  if (Status e = write_loglog_plot(panels, a.plot); !e) {
    std::cerr << e.error().format();
    return kInputError;
  }
  std::cerr << "sylva bench gpu --fog: wrote " << a.csv << " and " << a.plot << "\n";
  return failed > 0 ? kInputError : kOk;
}

}  // namespace sylva::cli

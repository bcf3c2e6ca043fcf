#include "render_setup.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <sstream>

#include "amalgam/hierarchy/build/build.h"
#include "amalgam/io/image.h"
#include "amalgam/io/render_outputs.h"
#include "amalgam/util/atomic_file.h"
#include "amalgam/util/file_kind.h"

namespace amalgam::cli {
namespace {

/// The files a render writes, by option (an empty path: not written).
std::vector<OutputFile> outputs(const RenderExtras& e, const std::string& ckpt) {
  return {{"--out", e.out},
          {"--cost-image", e.cost_image},
          {"--cost-legend", e.cost_legend},
          {"--level-image", e.level_image},
          {"--stats", e.stats},
          {"--checkpoint", ckpt}};
}

/// The --footprint value of `lod` (1, the default, where there is none), as fingerprints and
/// the EXR header spell it.
float footprint_of(const LevelOfDetail& lod) {
  if (const auto* f = std::get_if<ByFootprint>(&lod)) return f->pixels;
  if (const auto* c = std::get_if<VolumetricCells>(&lod)) return c->cone_widths;
  return 1.0f;
}

}  // namespace

std::string fingerprint(const CommonOptions& c, const LoadedScene& scene) {
  const RenderOptions& o = c.options;
  std::ostringstream f;
  f << c.scene << " (scene " << std::hex << content_hash(scene) << std::dec << ")"
    << " --renderer " << c.renderer << " --opacity " << c.opacity << " --order " << c.order
    << " --seed " << o.seed << " --width " << o.width << " --height " << o.height;
  if (const auto* l = std::get_if<OnLevel>(&o.lod))
    f << " --level " << l->level;
  else
    f << " --footprint " << footprint_of(o.lod);
  if (o.tracer == TracerKind::kEmbree) f << " --tracer embree";  // amalgam's: as before
  // Only when not the default, so checkpoints written before the option existed still resume.
  if (o.sampler == PixelSampler::kStratified) f << " --sampler stratified";
  return f.str();
}

void make_output_dir(const std::string& option, const std::string& dir,
                     const std::vector<OutputFile>& outs, const std::string& scene) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw InputError(option + " " + dir + ": exists and is not a directory");
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir, ec))
    throw InputError(option + " " + dir + ": cannot create the directory: " + ec.message());
  check_files(outs, scene);
}

void check_outputs_spare_inputs(const RenderExtras& e, const std::string& ckpt,
                                const LoadedScene& scene) {
  check_files_spare_inputs(outputs(e, ckpt), scene);
}

void check_files_spare_inputs(const std::vector<OutputFile>& outs, const LoadedScene& scene) {
  std::vector<std::pair<std::string, const std::string*>> inputs;  // by identity
  for (const std::string& in : scene.inputs) inputs.emplace_back(file_identity(in), &in);
  for (const OutputFile& o : outs) {
    if (o.path.empty() || resolve_output(o.path).kind != OutputTarget::Kind::kFile) continue;
    const std::string key = file_identity(o.path);
    for (const auto& [identity, path] : inputs)
      if (identity == key)
        throw InputError(o.option + " " + o.path + ": " + *path + ", which the scene " +
                         scene.name + " reads (an output never replaces an input)");
  }
}

void check_outputs(const RenderExtras& e, const std::string& ckpt, const RenderOptions& ro,
                   const std::string& scene) {
  if (!e.cost_image.empty() && ro.tracer == TracerKind::kEmbree)
    throw InputError("--cost-image " + e.cost_image +
                     ": --tracer embree counts no intersection tests (no cost image)");
  if (!is_image_path(e.out))
    throw InputError("--out " + e.out + ": unsupported image format (expected .png, .exr or .pfm)");
  if (!e.cost_image.empty() && !is_image_path(e.cost_image))
    throw InputError("--cost-image " + e.cost_image +
                     ": unsupported image format (expected .png, .exr or .pfm)");
  if (!e.cost_legend.empty() && (!is_png_path(e.cost_legend) || !is_png_path(e.cost_image)))
    throw InputError("--cost-legend " + e.cost_legend +
                     ": the colour bar of a PNG --cost-image, itself a PNG (.png)");
  if (!e.level_image.empty() && !is_image_path(e.level_image))
    throw InputError("--level-image " + e.level_image +
                     ": unsupported image format (expected .png, .exr or .pfm)");
  check_files(outputs(e, ckpt), scene);
}

void check_files(const std::vector<OutputFile>& outs, const std::string& scene) {
  std::error_code ec;
  const bool scene_file = scene.rfind("builtin:", 0) != 0 && std::filesystem::exists(scene, ec);
  const std::string input = scene_file ? file_identity(scene) : std::string();
  std::vector<std::pair<std::string, const std::string*>> files;  // regular files, by identity
  for (const OutputFile& o : outs) {
    if (o.path.empty()) continue;
    check_writable(o.path);
    const OutputTarget t = resolve_output(o.path);
    if (t.kind != OutputTarget::Kind::kFile) continue;  // devices and "-" may be shared
    const std::string key = file_identity(o.path);
    if (key == input)
      throw InputError(o.option + " " + o.path + ": the scene " + scene +
                       " itself (an output never replaces an input)");
    for (const auto& [other, option] : files)
      if (other == key) throw InputError(o.option + " " + o.path + ": the same file as " + *option);
    files.emplace_back(key, &o.option);
  }
}

std::uint64_t physical_memory() {
  return static_cast<std::uint64_t>(sysconf(_SC_PHYS_PAGES)) *
         static_cast<std::uint64_t>(sysconf(_SC_PAGE_SIZE));
}

std::uint64_t film_bytes(const RenderOptions& o) {
  const std::uint64_t pixels = static_cast<std::uint64_t>(o.width) * o.height;
  return MemoryModel::kProcess + pixels * MemoryModel::kPerPixel;
}

LogRange parse_cost_range(const std::string& text) {
  const std::string what = "--cost-range " + text + ": ";
  const std::size_t comma = text.find(',');
  if (comma == std::string::npos)
    throw InputError(what + "expected two numbers MIN,MAX (e.g. 10,1000)");
  double v[2];
  const std::string parts[2] = {text.substr(0, comma), text.substr(comma + 1)};
  for (int k = 0; k < 2; ++k) {
    std::size_t end = 0;
    try {
      v[k] = std::stod(parts[k], &end);
    } catch (const std::exception&) {
      end = 0;
    }
    if (parts[k].empty() || end != parts[k].size() || !std::isfinite(v[k]))
      throw InputError(what + "expected two numbers MIN,MAX (e.g. 10,1000)");
  }
  if (!(v[0] > 0.0))
    throw InputError(what + "MIN must be greater than 0 on the log scale of the cost image");
  if (!(v[0] < v[1])) throw InputError(what + "MIN must be less than MAX");
  return {v[0], v[1]};
}

std::string command_text(const std::vector<std::string>& argv) {
  std::string out;
  for (std::size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (i > 0 && a == "--threads") {
      ++i;  // and its value
      continue;
    }
    if (a.starts_with("--threads=") || a == "--resume") continue;  // same image either way
    if (!out.empty()) out += ' ';
    const bool plain = !a.empty() && a.find_first_not_of(
                                         "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMN"
                                         "OPQRSTUVWXYZ0123456789-_.,:/=+@%") == std::string::npos;
    if (plain) {
      out += a;
      continue;
    }
    out += '\'';
    for (char c : a) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    out += '\'';
  }
  return out;
}

std::string options_text(const CommonOptions& c, int spp) {
  const RenderOptions& o = c.options;
  std::ostringstream f;
  f << "--renderer " << c.renderer << " --opacity " << c.opacity << " --order " << c.order;
  if (const auto* l = std::get_if<OnLevel>(&o.lod))
    f << " --level " << l->level;
  else if (o.renderer() != RendererKind::kTraditional)
    f << " --footprint " << footprint_of(o.lod);
  f << " --seed " << o.seed << " --width " << o.width << " --height " << o.height << " --spp "
    << spp;
  return f.str();
}

std::uint64_t peak_memory_bytes() {
  rusage u{};
  if (getrusage(RUSAGE_SELF, &u) != 0) return 0;
  return static_cast<std::uint64_t>(u.ru_maxrss) * 1024;  // Linux: kibibytes
}

std::string format_range(const LogRange& r) {
  std::ostringstream s;
  s << r.min << ".." << r.max;
  return s.str();
}

}  // namespace amalgam::cli

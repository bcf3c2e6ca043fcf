#pragma once
/// \file What `amalgam render` checks and records around a render: its output paths, its
/// memory budget, the fingerprint a checkpoint is resumed under, and the command-line text of
/// the EXR header (render_cmd.cpp runs the render itself).

#include <cstdint>
#include <string>
#include <vector>

#include "amalgam/io/colormap.h"
#include "amalgam/load/load_scene.h"
#include "common.h"

namespace amalgam::cli {

/// Everything that determines the image except spp and threads: the renderer options and the
/// scene as loaded (content_hash: its geometry, lights and camera, or a builtin's parameters
/// as applied). A checkpoint is only resumed under the same fingerprint.
std::string fingerprint(const CommonOptions& c, const LoadedScene& scene);

/// An output file and the option that names it (an empty path: not written).
struct OutputFile {
  std::string option;
  std::string path;
};

/// Every subcommand's check of its output files before any work: each writable, no two the
/// same file, none the scene file (by file identity: device and inode, or the resolved path of
/// a new file). Throws InputError.
void check_files(const std::vector<OutputFile>& outs, const std::string& scene);

/// Creates the directory `dir` that `option` names (the caller's other checks come first, so
/// that a refused command leaves no directory behind) and checks `outs`, the files to be written
/// there, with check_files. Throws InputError.
void make_output_dir(const std::string& option, const std::string& dir,
                     const std::vector<OutputFile>& outs, const std::string& scene);

/// Once the scene is loaded, before anything is written: no output on a file it read (the
/// meshes a scene file names and every file their import read). Throws InputError.
void check_files_spare_inputs(const std::vector<OutputFile>& outs, const LoadedScene& scene);

/// Checks every output path before any work: an image path must name a format we write, every
/// path must be writable, no two outputs may be the same file and none may be the scene file
/// (compared by file identity: device and inode, or the resolved path of a new file). Throws
/// InputError.
void check_outputs(const RenderExtras& e, const std::string& ckpt, const RenderOptions& ro,
                   const std::string& scene);

/// Once the scene is loaded, before anything is written: no output on a file it read (the
/// meshes a scene file names and the textures they name; the scene file itself was checked
/// before loading). Throws InputError.
void check_outputs_spare_inputs(const RenderExtras& e, const std::string& ckpt,
                                const LoadedScene& scene);

/// The machine's physical memory in bytes (the default --max-memory).
std::uint64_t physical_memory();

/// Bytes a render of these options needs beyond the scene: the process and the film (sums,
/// tests, image and cost per pixel; MemoryModel, hierarchy/build/build.h).
std::uint64_t film_bytes(const RenderOptions& o);

/// "--cost-range MIN,MAX": two finite numbers, 0 < MIN < MAX (a log scale). Throws InputError.
LogRange parse_cost_range(const std::string& text);

/// The command line as one string, each argument that needs it in single quotes, without
/// --threads and --resume: it goes into the EXR header, which is part of the file's bytes, and
/// those are the same for any thread count (the stats hold the threads used) and whether the
/// render was resumed or not.
std::string command_text(const std::vector<std::string>& argv);

/// The renderer options as command-line text (the EXR header's "amalgam:options").
std::string options_text(const CommonOptions& c, int spp);

/// The process's peak resident memory in bytes (0 where unknown).
std::uint64_t peak_memory_bytes();

/// "MIN..MAX", as the messages print a cost range.
std::string format_range(const LogRange& r);

}  // namespace amalgam::cli

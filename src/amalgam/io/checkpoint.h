#pragma once
/// \file Checkpoints of progressive renders: the FilmState plus a fingerprint of everything
/// that determines the image (scene, parameters, options other than spp and threads), so a
/// render is only ever resumed with the settings it was started with.

#include <cstdint>
#include <string>
#include <string_view>

#include "amalgam/render/render.h"

namespace amalgam {

/// Writes `state` atomically (util/atomic_file.h). Throws RuntimeError on failure.
void write_checkpoint(const std::string& path, const std::string& fingerprint,
                      const FilmState& state);

/// The film a checkpoint must hold (a width of 0: any).
struct FilmSize {
  int width = 0, height = 0;
};

/// Reads a checkpoint; throws InputError naming the file when it is unreadable, corrupt, or
/// was written for a different fingerprint or film. The header is checked against both before
/// the body is read: no more than this render's film is ever held.
FilmState read_checkpoint(const std::string& path, const std::string& fingerprint,
                          FilmSize film = {});

/// True when `path` is a regular file that begins as a checkpoint written for `fingerprint`
/// (its magic and fingerprint; the rest is not read). False on any error: what a completed
/// render may remove is only its own checkpoint, never a file that merely sits at that path.
bool is_checkpoint_of(const std::string& path, const std::string& fingerprint);

/// The checksum a checkpoint ends with (8 bytes), of all the bytes before it: for the tests and
/// the fuzzer (fuzz/checkpoint_fuzz.cpp), which make checkpoints that pass it to reach the
/// checks behind it.
std::uint64_t checkpoint_checksum(std::string_view bytes);

}  // namespace amalgam

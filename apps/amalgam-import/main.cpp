/// `amalgam-import --parent PID --max-triangles N [--max-bytes B --limit-name TEXT] -- MESH`:
/// the mesh import helper. Runs Assimp
/// on MESH (io/assimp_import.h) and writes the reply to stdout (io/import_protocol.h): the
/// triangles, or the InputError's message. Started by import_mesh (io/mesh_import.h), never by
/// hand: a crash here, on a corrupt file, is one InputError there, not a crash of amalgam.
///
/// Exit status: 0 when the reply was written (a mesh or an error), 1 when it could not be,
/// 2 on bad arguments. It dies with the process that started it (PR_SET_PDEATHSIG). With
/// --max-bytes, it allocates at most B bytes (RLIMIT_DATA; not under AddressSanitizer, whose
/// shadow memory would count): an import that needs more replies "the importer ran out of
/// memory under TEXT".

#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include "amalgam/io/assimp_import.h"
#include "amalgam/io/import_protocol.h"

#if defined(__SANITIZE_ADDRESS__)
#define AMALGAM_IMPORT_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define AMALGAM_IMPORT_UNDER_ASAN 1
#endif
#endif

namespace {

bool parse_number(const char* text, std::uint64_t& out) {
  const std::string s = text;
  if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos || s.size() > 19)
    return false;
  out = std::stoull(s);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  std::uint64_t parent = 0;
  amalgam::ImportConfig config;
  std::string path;
  std::uint64_t max_bytes = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--parent" && i + 1 < argc && parse_number(argv[i + 1], parent)) {
      ++i;
    } else if (a == "--max-triangles" && i + 1 < argc &&
               parse_number(argv[i + 1], config.max_triangles)) {
      ++i;
    } else if (a == "--max-bytes" && i + 1 < argc && parse_number(argv[i + 1], max_bytes)) {
      ++i;
    } else if (a == "--limit-name" && i + 1 < argc) {
      config.limit_name = argv[++i];
    } else if (a == "--smooth-normals") {
      config.smooth_normals = true;
    } else if (a == "--" && i + 2 == argc) {
      path = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: amalgam-import --parent PID --max-triangles N [--max-bytes B "
                   "--limit-name TEXT] [--smooth-normals] -- MESH (started by amalgam, which reads "
                   "its stdout)\n");
      return 2;
    }
  }
  if (path.empty() || parent == 0) {
    std::fprintf(stderr, "amalgam-import: --parent and MESH are required\n");
    return 2;
  }
  // Die with the parent; if it is already gone (we were reparented before prctl), stop now.
  if (::prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || static_cast<std::uint64_t>(::getppid()) != parent)
    return 1;

#ifndef AMALGAM_IMPORT_UNDER_ASAN
  if (max_bytes != 0) {
    const rlimit limit{max_bytes, max_bytes};
    if (::setrlimit(RLIMIT_DATA, &limit) != 0) return 1;
  }
#endif

  bool sent = false;
  try {
    sent = amalgam::import_protocol::send_mesh(1, amalgam::import_with_assimp(path, config));
  } catch (const std::bad_alloc&) {
    sent = amalgam::import_protocol::send_error(1, amalgam::out_of_memory_message(path, config));
  } catch (const std::exception& e) {
    sent = amalgam::import_protocol::send_error(1, e.what());
  }
  return sent ? 0 : 1;
}

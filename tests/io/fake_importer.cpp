/// A stand-in for the amalgam-import helper (apps/amalgam-import), for tests/io/import_test.cpp
/// and the CLI tests: tests point ImportConfig::helper or AMALGAM_IMPORT_HELPER at it to see
/// how import_mesh copes with a helper that misbehaves. Takes the helper's arguments; what it
/// does depends on the mesh file's stem:
///   too-many        replies with 2 triangles whatever --max-triangles says, then waits forever
///   other-protocol  replies in another protocol, then waits forever
///   never-answers   waits forever without a word (as an importer caught in a loop would)
///   anything else   aborts (SIGABRT), as Assimp 5.2 does on some corrupt files

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "amalgam/io/import_protocol.h"

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  const std::string mesh = argv[argc - 1];
  const std::string stem = std::filesystem::path(mesh).stem().string();
  if (stem == "too-many") {
    amalgam::ImportedMesh m;
    m.triangles = {amalgam::Primitive::triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}),
                   amalgam::Primitive::triangle({0, 0, 0}, {0, 1, 0}, {0, 0, 1})};
    m.materials.resize(1);
    if (!amalgam::import_protocol::send_mesh(1, m)) return 1;
  } else if (stem == "other-protocol") {
    const std::string hello = "amalgam-import protocol 0";
    const std::uint64_t n = hello.size();
    if (::write(1, &n, sizeof n) != sizeof n || ::write(1, hello.data(), n) != ssize_t(n)) return 1;
  } else if (stem != "never-answers") {
    std::abort();
  }
  for (;;) ::pause();
}

#include "amalgam/io/mesh_check.h"

#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "amalgam/util/error.h"

namespace amalgam {

namespace {

/// The lines of `in` that hold something (not blank, not a # comment).
bool next_content_line(std::istream& in, std::string& line) {
  while (std::getline(in, line)) {
    const std::size_t at = line.find_first_not_of(" \t\r");
    if (at != std::string::npos && line[at] != '#') return true;
  }
  return false;
}

/// An OFF body's face indices are vertex numbers: whole numbers below `nv` (Assimp 5.2 reads
/// -1 or 1.5 as some vertex and renders the file).
void check_off_faces(const std::string& path, std::istream& in, std::uint64_t nv,
                     std::uint64_t nf) {
  std::string line;
  std::getline(in, line);  // the rest of the counts' line
  for (std::uint64_t v = 0; v < nv; ++v)
    if (!next_content_line(in, line)) return;  // short files are Assimp's to refuse
  for (std::uint64_t f = 0; f < nf && next_content_line(in, line); ++f) {
    std::istringstream words(line);
    std::uint64_t k = 0;
    if (!(words >> k)) return;
    std::string index;
    for (std::uint64_t i = 0; i < k && words >> index; ++i) {
      const bool digits = index.find_first_not_of("0123456789") == std::string::npos;
      if (!digits || index.size() > 19 || std::stoull(index) >= nv)
        fail_input(path, "face " + std::to_string(f) + " has vertex index '" + index.substr(0, 24) +
                             "': expected a whole number below " + std::to_string(nv) +
                             ", the vertices the header declares");
    }
  }
}

}  // namespace

void check_mesh_file(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  std::error_code ec;
  const std::uint64_t file_size = std::filesystem::file_size(path, ec);
  if (ec) return;
  char magic[4] = {};
  std::ifstream(path, std::ios::binary).read(magic, 4);
  detail::check_gltf(path, ext, magic, file_size);
  // Assimp also picks its PLY reader by content for other extensions.
  if (ext != ".off" && ext != ".ply") {
    if (std::string(magic, 3) != "ply" || (magic[3] != '\n' && magic[3] != '\r')) return;
    ext = ".ply";
  }
  const auto size = static_cast<double>(file_size);
  std::ifstream in(path, std::ios::binary);
  std::string line;
  auto too_many = [&](double count, const char* what) {
    // Every vertex or face takes at least two bytes in any encoding Assimp reads.
    if (count * 2.0 > size) {
      std::ostringstream m;
      m << "the header declares " << count << " " << what << " but the file has only "
        << static_cast<std::uint64_t>(size) << " bytes";
      fail_input(path, m.str());
    }
  };
  if (ext == ".off") {
    // "OFF" (possibly with prefixes such as C, N, ST) then "nv nf ne", possibly on one line.
    std::string word;
    if (!(in >> word) || word.find("OFF") == std::string::npos) return;
    double nv = 0, nf = 0;
    std::istringstream counts(word.substr(word.find("OFF") + 3));
    if (!(counts >> nv >> nf) && !(in >> nv >> nf)) return;
    too_many(nv, "vertices");
    too_many(nf, "faces");
    check_off_faces(path, in, static_cast<std::uint64_t>(nv), static_cast<std::uint64_t>(nf));
  } else {
    // The header grammar is checked: Assimp 5.2 crashes on some malformed headers (reads
    // past a header without end_header; asserts in its triangulation on faces read through a
    // garbled element or property line). Found by fuzz/mesh_fuzz.cpp; see
    // tests/fuzz_regressions_test.cpp.
    bool end = false;
    std::set<std::string> elements;
    int properties = 0;
    for (int i = 0; i < 100'000 && std::getline(in, line); ++i) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      std::istringstream words(line);
      std::vector<std::string> w;
      for (std::string word; words >> word;) w.push_back(word);
      const std::string kw = w.empty() ? "" : w[0];
      if (kw == "end_header" && w.size() == 1) {
        end = true;
        break;
      }
      // element and property lines exactly as the format says; other lines (format, comment,
      // and the bare comments that some exporters write, e.g. Wuson.ply's) must be text.
      // Elements have unique names and at least one property; property types are PLY's.
      static const std::set<std::string> kTypes = {
          "char", "uchar", "short", "ushort", "int",   "uint",   "float",   "double",
          "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
      bool ok =
          kw == "element" ? w.size() == 3 && elements.insert(w[1]).second &&
                                (properties > 0 || elements.size() == 1)
          : kw == "property"
              ? !elements.empty() &&
                    ((w.size() == 3 && kTypes.count(w[1])) ||
                     (w.size() == 5 && w[1] == "list" && kTypes.count(w[2]) && kTypes.count(w[3])))
              : true;
      // A garbled structural keyword ("property~", "elemen") is not a bare comment: Assimp
      // reads it as the keyword and miscounts the properties.
      for (const char* k : {"element", "property", "end_header", "format"}) {
        const std::string key = k;
        if (kw != key && !kw.empty() && (kw.starts_with(key) || key.starts_with(kw))) ok = false;
      }
      if (kw == "element") properties = 0;
      if (kw == "property") ++properties;
      for (char c : line)
        ok = ok && (c == '\t' ||
                    (static_cast<unsigned char>(c) >= 32 && static_cast<unsigned char>(c) < 127));
      if (!ok) {
        std::string shown = line.substr(0, 60);
        for (char& c : shown)
          if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
        fail_input(path,
                   "malformed PLY header: line " + std::to_string(i + 1) + " is '" + shown + "'");
      }
      if (kw == "element") {
        double count = 0;
        std::istringstream(w[2]) >> count;
        too_many(count, "elements");
      }
    }
    if (!end) fail_input(path, "malformed PLY header: no 'end_header' line");
    if (!elements.empty() && properties == 0)
      fail_input(path, "malformed PLY header: the last element has no properties");
  }
}

}  // namespace amalgam

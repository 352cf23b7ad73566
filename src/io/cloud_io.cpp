#include "cube_scan_matcher/io/cloud_io.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

namespace cube_scan_matcher::io {
namespace {

[[noreturn]] void fail(const std::string& name, const std::string& what) {
  throw CloudFileError(name + ": " + what);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::vector<std::string> words(const std::string& line) {
  std::istringstream ss(line);
  std::vector<std::string> out;
  for (std::string w; ss >> w;) out.push_back(w);
  return out;
}

/// A non-negative integer of at most `max`, or fail naming `what`.
std::size_t count(const std::string& name, const std::string& what, const std::string& text,
                  std::size_t max) {
  if (text.empty() || text.size() > 19 ||
      !std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isdigit(c); })) {
    fail(name, what + " '" + text + "' is not a non-negative integer");
  }
  const unsigned long long v = std::stoull(text);
  if (v > max) fail(name, what + " " + text + " is above the limit of " + std::to_string(max));
  return std::size_t(v);
}

/// One scalar field of a point record: its byte offset and type.
struct Field {
  std::string name;
  char type = 'F';        // 'F' float, 'I' signed, 'U' unsigned
  std::size_t size = 4;   // bytes of one element
  std::size_t count = 1;  // elements
  std::size_t offset = 0;
};

/// The byte offsets of x, y, z in a record of `fields`; each must be one F4 or F8 element.
struct XyzLayout {
  const Field* f[3] = {nullptr, nullptr, nullptr};
};
XyzLayout findXyz(const std::string& name, const std::vector<Field>& fields) {
  XyzLayout l;
  const char* axes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    for (const Field& f : fields) {
      if (f.name == axes[k]) l.f[k] = &f;
    }
    if (!l.f[k]) fail(name, std::string("no '") + axes[k] + "' field");
    const Field& f = *l.f[k];
    if (f.type != 'F' || (f.size != 4 && f.size != 8) || f.count != 1) {
      fail(name, std::string("field '") + axes[k] + "' must be one float or double, got type " +
                     f.type + " size " + std::to_string(f.size) + " count " +
                     std::to_string(f.count));
    }
  }
  return l;
}

double readScalar(const unsigned char* p, std::size_t size, bool big_endian) {
  unsigned char b[8];
  std::memcpy(b, p, size);
  if (big_endian) std::reverse(b, b + size);
  if (size == 4) {
    float v;
    std::memcpy(&v, b, 4);
    return v;
  }
  double v;
  std::memcpy(&v, b, 8);
  return v;
}

/// Checks the points against the limits (no point, no finite point, absurd coordinates).
void checkPoints(const std::string& name, const PointArray& p, const CloudReadLimits& limits) {
  if (p.empty()) fail(name, "cloud has no points");
  std::size_t finite = 0, absurd = 0;
  double worst = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double c[3] = {p.x[i], p.y[i], p.z[i]};
    if (!(std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2]))) continue;
    ++finite;
    for (double v : c) {
      if (std::abs(v) > limits.max_abs_coordinate) {
        ++absurd;
        worst = std::max(worst, std::abs(v));
      }
    }
  }
  if (finite == 0) {
    fail(name, "no finite point (" + std::to_string(p.size()) + " points, all NaN or inf)");
  }
  if (absurd > 0) {
    std::ostringstream os;
    os << absurd << " coordinates beyond " << limits.max_abs_coordinate << " m (up to " << worst
       << " m): not a scan in metres";
    fail(name, os.str());
  }
}

/// Reads `n` records of `record` bytes from `data` (little-endian unless big_endian).
PointArray readRecords(const unsigned char* data, std::size_t n, std::size_t record,
                       const XyzLayout& xyz, bool big_endian) {
  PointArray out;
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned char* r = data + i * record;
    out.push_back(float(readScalar(r + xyz.f[0]->offset, xyz.f[0]->size, big_endian)),
                  float(readScalar(r + xyz.f[1]->offset, xyz.f[1]->size, big_endian)),
                  float(readScalar(r + xyz.f[2]->offset, xyz.f[2]->size, big_endian)));
  }
  return out;
}

/// ASCII records from `text`: one point per line, the fields' elements in order.
PointArray readAsciiRecords(const std::string& name, const std::string& text, std::size_t pos,
                            std::size_t n, const std::vector<Field>& fields,
                            const XyzLayout& xyz) {
  std::size_t elements = 0;
  for (const Field& f : fields) elements += f.count;
  std::size_t index_of[3];  // element index of x, y, z within a line
  for (int k = 0; k < 3; ++k) {
    index_of[k] = 0;
    for (const Field& f : fields) {
      if (&f == xyz.f[k]) break;
      index_of[k] += f.count;
    }
  }
  PointArray out;
  std::size_t line_no = 0;
  while (out.size() < n) {
    if (pos >= text.size()) {
      fail(name, "truncated: " + std::to_string(out.size()) + " of " + std::to_string(n) +
                     " declared points");
    }
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    const std::vector<std::string> w = words(text.substr(pos, end - pos));
    pos = end + 1;
    ++line_no;
    if (w.empty()) continue;
    if (w.size() != elements) {
      fail(name, "point line " + std::to_string(line_no) + " has " + std::to_string(w.size()) +
                     " values, the header declares " + std::to_string(elements));
    }
    float c[3];
    for (int k = 0; k < 3; ++k) {
      const std::string& s = w[index_of[k]];
      char* stop = nullptr;
      const double v = std::strtod(s.c_str(), &stop);
      if (stop == s.c_str() || *stop != '\0') {
        fail(name, "point line " + std::to_string(line_no) + ": '" + s + "' is not a number");
      }
      c[k] = float(v);
    }
    out.push_back(c[0], c[1], c[2]);
  }
  return out;
}

/// LZF decompression (the format of PCD's binary_compressed), every access bounds-checked.
/// Returns false on corrupt input or when the output would not be exactly out_len bytes.
bool lzfDecompress(const unsigned char* in, std::size_t in_len, unsigned char* out,
                   std::size_t out_len) {
  std::size_t ip = 0, op = 0;
  while (ip < in_len) {
    const unsigned ctrl = in[ip++];
    if (ctrl < 32) {  // a literal run of ctrl + 1 bytes
      const std::size_t len = ctrl + 1;
      if (ip + len > in_len || op + len > out_len) return false;
      std::memcpy(out + op, in + ip, len);
      ip += len;
      op += len;
    } else {  // a back reference: length (ctrl >> 5) + 2, distance from the next byte(s)
      std::size_t len = ctrl >> 5;
      if (len == 7) {
        if (ip >= in_len) return false;
        len += in[ip++];
      }
      len += 2;
      if (ip >= in_len) return false;
      const std::size_t back = ((std::size_t(ctrl) & 0x1f) << 8) + in[ip++] + 1;
      if (back > op || op + len > out_len) return false;
      for (std::size_t k = 0; k < len; ++k, ++op) out[op] = out[op - back];  // may overlap
    }
  }
  return op == out_len;
}

PointArray parsePcd(const std::string& name, const std::string& bytes,
                    const CloudReadLimits& limits) {
  std::vector<Field> fields;
  std::vector<std::string> sizes, types, counts;
  std::size_t width = 0, height = 1, points = 0;
  bool have_points = false, have_width = false;
  std::string data;
  std::size_t pos = 0;
  while (data.empty()) {
    if (pos >= bytes.size()) fail(name, "PCD header ends before its DATA line");
    if (pos > limits.max_header_bytes) fail(name, "PCD header longer than its limit (no DATA line)");
    std::size_t end = bytes.find('\n', pos);
    const bool last = end == std::string::npos;  // the file ends inside this line
    if (last) end = bytes.size();
    const std::string line = bytes.substr(pos, end - pos);
    pos = std::min(end + 1, bytes.size());
    const std::vector<std::string> w = words(line);
    if (last && (w.empty() || w[0] != "DATA")) {
      fail(name, "PCD header ends before its DATA line (truncated?)");
    }
    if (w.empty() || w[0][0] == '#') continue;
    const std::string key = w[0];
    const std::vector<std::string> args(w.begin() + 1, w.end());
    if (key == "VERSION" || key == "VIEWPOINT") continue;
    if (key == "FIELDS" || key == "COLUMNS") {
      for (const std::string& a : args) fields.push_back(Field{a, 'F', 4, 1, 0});
    } else if (key == "SIZE") {
      sizes = args;
    } else if (key == "TYPE") {
      types = args;
    } else if (key == "COUNT") {
      counts = args;
    } else if (key == "WIDTH" && args.size() == 1) {
      width = count(name, "WIDTH", args[0], limits.max_points);
      have_width = true;
    } else if (key == "HEIGHT" && args.size() == 1) {
      height = count(name, "HEIGHT", args[0], limits.max_points);
    } else if (key == "POINTS" && args.size() == 1) {
      points = count(name, "POINTS", args[0], limits.max_points);
      have_points = true;
    } else if (key == "DATA" && args.size() == 1) {
      data = lower(args[0]);
    } else {
      fail(name, "not a PCD header line: '" + line.substr(0, 60) + "'");
    }
  }
  if (fields.empty()) fail(name, "PCD header has no FIELDS");
  if (sizes.size() != fields.size() || types.size() != fields.size() ||
      (!counts.empty() && counts.size() != fields.size())) {
    fail(name, "PCD header: FIELDS, SIZE, TYPE and COUNT do not have the same length");
  }
  std::size_t record = 0;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    Field& f = fields[i];
    f.size = count(name, "SIZE", sizes[i], 8);
    if (types[i].size() != 1 || std::string("FIU").find(types[i][0]) == std::string::npos) {
      fail(name, "PCD TYPE '" + types[i] + "' is not F, I or U");
    }
    f.type = types[i][0];
    if (f.size != 1 && f.size != 2 && f.size != 4 && f.size != 8) {
      fail(name, "PCD SIZE " + sizes[i] + " is not 1, 2, 4 or 8");
    }
    f.count = counts.empty() ? 1 : count(name, "COUNT", counts[i], 1 << 20);
    if (f.count == 0) fail(name, "PCD COUNT of '" + f.name + "' is 0");
    f.offset = record;
    record += f.size * f.count;
  }
  if (!have_points) points = width * height;
  if (points > limits.max_points) {
    fail(name, "PCD declares " + std::to_string(points) + " points, above the limit of " +
                   std::to_string(limits.max_points));
  }
  if (have_width && width * height != points) {
    fail(name, "PCD WIDTH x HEIGHT = " + std::to_string(width * height) + " but POINTS = " +
                   std::to_string(points));
  }
  if (points == 0) fail(name, "cloud has no points (POINTS 0)");
  const XyzLayout xyz = findXyz(name, fields);
  const std::size_t body = bytes.size() - pos;
  const auto* raw = reinterpret_cast<const unsigned char*>(bytes.data()) + pos;
  if (data == "ascii") return readAsciiRecords(name, bytes, pos, points, fields, xyz);
  if (data == "binary") {
    if (body / record < points) {
      fail(name, "truncated body: " + std::to_string(body) + " bytes for " +
                     std::to_string(points) + " declared points of " + std::to_string(record) +
                     " bytes");
    }
    return readRecords(raw, points, record, xyz, false);
  }
  if (data == "binary_compressed") {
    if (body < 8) fail(name, "truncated body: no compressed-size words");
    std::uint32_t compressed = 0, uncompressed = 0;
    std::memcpy(&compressed, raw, 4);
    std::memcpy(&uncompressed, raw + 4, 4);
    if (std::uint64_t(uncompressed) != std::uint64_t(points) * record) {
      fail(name, "compressed body declares " + std::to_string(uncompressed) + " bytes, the header " +
                     std::to_string(points) + " points of " + std::to_string(record) + " bytes");
    }
    // One LZF input byte yields at most 88 output bytes (a 3-byte back reference of 264): a
    // larger declared size is a lie, refused before any allocation.
    if (std::uint64_t(uncompressed) > 100 * std::uint64_t(compressed) + 64) {
      fail(name, "compressed body declares " + std::to_string(uncompressed) +
                     " bytes from only " + std::to_string(compressed) + " compressed bytes");
    }
    if (compressed > body - 8) {
      fail(name, "truncated body: " + std::to_string(body - 8) + " of " +
                     std::to_string(compressed) + " compressed bytes");
    }
    std::vector<unsigned char> soa(uncompressed);
    if (!lzfDecompress(raw + 8, compressed, soa.data(), soa.size())) {
      fail(name, "compressed body is corrupt (LZF)");
    }
    // binary_compressed stores each field for all points in turn: x of every point, then y...
    PointArray out;
    out.reserve(points);
    std::size_t field_start[3];
    for (int k = 0; k < 3; ++k) field_start[k] = xyz.f[k]->offset * points;
    for (std::size_t i = 0; i < points; ++i) {
      float c[3];
      for (int k = 0; k < 3; ++k) {
        const std::size_t s = xyz.f[k]->size;
        c[k] = float(readScalar(soa.data() + field_start[k] + i * s, s, false));
      }
      out.push_back(c[0], c[1], c[2]);
    }
    return out;
  }
  fail(name, "PCD DATA '" + data + "' is not ascii, binary or binary_compressed");
}

PointArray parsePly(const std::string& name, const std::string& bytes,
                    const CloudReadLimits& limits) {
  std::size_t pos = 0;
  auto nextLine = [&]() {
    if (pos >= bytes.size()) fail(name, "PLY header ends before end_header");
    if (pos > limits.max_header_bytes) fail(name, "PLY header longer than its limit");
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string::npos) end = bytes.size();
    std::string line = bytes.substr(pos, end - pos);
    pos = std::min(end + 1, bytes.size());
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line;
  };
  if (nextLine() != "ply") fail(name, "not a PLY file (first line is not 'ply')");
  std::string format;
  bool in_vertex = false, vertex_first = false, seen_element = false;
  std::size_t vertices = 0;
  std::vector<Field> fields;
  std::size_t record = 0;
  for (std::string line = nextLine(); line != "end_header"; line = nextLine()) {
    const std::vector<std::string> w = words(line);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "format" && w.size() == 3) {
      format = w[1];
    } else if (w[0] == "element" && w.size() == 3) {
      in_vertex = w[1] == "vertex";
      if (in_vertex) {
        vertices = count(name, "vertex count", w[2], limits.max_points);
        vertex_first = !seen_element;
      }
      seen_element = true;
    } else if (w[0] == "property" && w.size() >= 3) {
      if (!in_vertex) continue;  // properties of other elements (faces) are not read
      if (w[1] == "list") fail(name, "PLY vertex has a list property, not supported");
      static const struct { const char* n; char t; std::size_t s; } kTypes[] = {
          {"char", 'I', 1},    {"int8", 'I', 1},   {"uchar", 'U', 1},  {"uint8", 'U', 1},
          {"short", 'I', 2},   {"int16", 'I', 2},  {"ushort", 'U', 2}, {"uint16", 'U', 2},
          {"int", 'I', 4},     {"int32", 'I', 4},  {"uint", 'U', 4},   {"uint32", 'U', 4},
          {"float", 'F', 4},   {"float32", 'F', 4}, {"double", 'F', 8}, {"float64", 'F', 8}};
      const auto* t = std::find_if(std::begin(kTypes), std::end(kTypes),
                                   [&](const auto& k) { return w[1] == k.n; });
      if (t == std::end(kTypes)) fail(name, "PLY property type '" + w[1] + "' is unknown");
      fields.push_back(Field{w[2], t->t, t->s, 1, record});
      record += t->s;
    } else {
      fail(name, "not a PLY header line: '" + line.substr(0, 60) + "'");
    }
  }
  if (vertices == 0) fail(name, "cloud has no points (no vertex element, or 0 vertices)");
  if (!vertex_first) fail(name, "PLY vertex element must be the first element");
  const XyzLayout xyz = findXyz(name, fields);
  if (format == "ascii") return readAsciiRecords(name, bytes, pos, vertices, fields, xyz);
  const bool big = format == "binary_big_endian";
  if (!big && format != "binary_little_endian") {
    fail(name, "PLY format '" + format + "' is not ascii, binary_little_endian or binary_big_endian");
  }
  const std::size_t body = bytes.size() - pos;
  if (body / record < vertices) {
    fail(name, "truncated body: " + std::to_string(body) + " bytes for " +
                   std::to_string(vertices) + " declared vertices of " + std::to_string(record) +
                   " bytes");
  }
  return readRecords(reinterpret_cast<const unsigned char*>(bytes.data()) + pos, vertices, record,
                     xyz, big);
}

}  // namespace

PointArray parseCloud(const std::string& name, const std::string& bytes,
                      const CloudReadLimits& limits) {
  const std::size_t dot = name.find_last_of('.');
  const std::string ext = dot == std::string::npos ? "" : lower(name.substr(dot + 1));
  if (ext != "pcd" && ext != "ply") {
    fail(name, "unknown extension '." + ext + "' (expected .pcd or .ply)");
  }
  if (bytes.empty()) fail(name, "empty file");
  PointArray p = ext == "pcd" ? parsePcd(name, bytes, limits) : parsePly(name, bytes, limits);
  checkPoints(name, p, limits);
  return p;
}

PointArray readCloudFile(const std::string& path, const CloudReadLimits& limits) {
  struct stat st;
  if (stat(path.c_str(), &st) != 0) fail(path, "no such file");
  if (S_ISDIR(st.st_mode)) fail(path, "is a directory, not a cloud file");
  if (!S_ISREG(st.st_mode)) fail(path, "not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot open: ") + std::strerror(errno));
  std::string bytes(std::size_t(st.st_size), '\0');
  if (!bytes.empty() && !in.read(&bytes[0], std::streamsize(bytes.size()))) {
    fail(path, "cannot read");
  }
  return parseCloud(path, bytes, limits);
}

}  // namespace cube_scan_matcher::io

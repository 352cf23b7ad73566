// The PCD/PLY reader on files it must read (every DATA kind, extra fields, doubles, big-endian)
// and on lies it must refuse with a message naming the problem, without allocating what a
// file merely declares.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include "cube_scan_matcher/io/cloud_io.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::io;

// The largest single allocation this test binary made since largest_allocation was reset
// (every std::vector and std::string goes through the global operator new replaced here).
namespace {
std::atomic<std::size_t> largest_allocation{0};
}  // namespace

void* operator new(std::size_t n) {
  std::size_t seen = largest_allocation.load(std::memory_order_relaxed);
  while (n > seen && !largest_allocation.compare_exchange_weak(seen, n)) {
  }
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

template <typename T>
void append(std::string& s, T v, bool big_endian = false) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big_endian) std::reverse(b, b + sizeof(T));
  s.append(b, sizeof(T));
}

std::string pcdHeader(const std::string& fields, const std::string& size, const std::string& type,
                      std::size_t n, const std::string& data) {
  std::string count;
  for (std::ptrdiff_t k = 0; k <= std::count(fields.begin(), fields.end(), ' '); ++k) count += " 1";
  return "VERSION 0.7\nFIELDS " + fields + "\nSIZE " + size + "\nTYPE " + type + "\nCOUNT" +
         count + "\nWIDTH " + std::to_string(n) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " +
         std::to_string(n) + "\nDATA " + data + "\n";
}

/// The expected points: x = i, y = 2 i, z = -i / 4.
void expectRamp(const PointArray& p, std::size_t n) {
  ASSERT_EQ(p.size(), n);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_FLOAT_EQ(p.x[i], float(i));
    EXPECT_FLOAT_EQ(p.y[i], 2.f * float(i));
    EXPECT_FLOAT_EQ(p.z[i], -float(i) / 4.f);
  }
}

std::string messageOf(const std::string& name, const std::string& bytes) {
  try {
    parseCloud(name, bytes);
  } catch (const CloudFileError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST(CloudIo, PcdBinaryWithExtraFieldsAndDoubles) {
  // x (F8), intensity (F4), y (F4), ring (U2), z (F8): offsets 0, 8, 12, 16, 18; record 26.
  std::string s = "FIELDS x intensity y ring z\nSIZE 8 4 4 2 8\nTYPE F F F U F\nCOUNT 1 1 1 1 1\n"
                  "WIDTH 5\nHEIGHT 1\nPOINTS 5\nDATA binary\n";
  for (int i = 0; i < 5; ++i) {
    append(s, double(i));
    append(s, 0.5f);
    append(s, float(2 * i));
    append(s, std::uint16_t(7));
    append(s, -double(i) / 4);
  }
  expectRamp(parseCloud("a.pcd", s), 5);
}

TEST(CloudIo, PcdAsciiAndCompressed) {
  std::string a = pcdHeader("x y z", "4 4 4", "F F F", 4, "ascii");
  for (int i = 0; i < 4; ++i) a += std::to_string(i) + " " + std::to_string(2 * i) + " " +
                                   std::to_string(-i / 4.0) + "\n";
  expectRamp(parseCloud("a.PCD", a), 4);

  // binary_compressed: the fields one after another (x of all points, then y, then z), LZF:
  // a literal run of the first 8 bytes, then a back reference that repeats them.
  std::string soa;
  for (float v : {0.f, 1.f, 0.f, 2.f, -0.f, -0.25f}) append(soa, v);  // x0 x1 y0 y1 z0 z1
  std::string lzf;
  lzf += char(soa.size() - 1);  // one literal run of all 24 bytes
  lzf += soa;
  std::string c = pcdHeader("x y z", "4 4 4", "F F F", 2, "binary_compressed");
  append(c, std::uint32_t(lzf.size()));
  append(c, std::uint32_t(soa.size()));
  c += lzf;
  expectRamp(parseCloud("c.pcd", c), 2);

  // A back reference: x of 4 points is 16 zero bytes = a literal run of 4 zero bytes, then a
  // copy of length 12 (code 7 + extra byte 3, + 2) from 4 bytes back (distance byte 3, + 1).
  std::string lzf2;
  lzf2 += char(3);
  lzf2.append(4, '\0');
  lzf2 += char(7 << 5);
  lzf2 += char(3);
  lzf2 += char(3);
  std::string yz;  // y = 2 i, z = -i / 4 of the 4 points, as one literal run of 32 bytes
  for (int i = 0; i < 4; ++i) append(yz, float(2 * i));
  for (int i = 0; i < 4; ++i) append(yz, -float(i) / 4);
  lzf2 += char(yz.size() - 1);
  lzf2 += yz;
  std::string z = pcdHeader("x y z", "4 4 4", "F F F", 4, "binary_compressed");
  append(z, std::uint32_t(lzf2.size()));
  append(z, std::uint32_t(48));
  z += lzf2;
  const PointArray pz = parseCloud("z.pcd", z);
  ASSERT_EQ(pz.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(pz.x[i], 0.f);
    EXPECT_FLOAT_EQ(pz.y[i], 2.f * float(i));
    EXPECT_FLOAT_EQ(pz.z[i], -float(i) / 4.f);
  }
  // A reference before the start of the output is corrupt, not a read out of bounds.
  std::string bad = pcdHeader("x y z", "4 4 4", "F F F", 1, "binary_compressed");
  append(bad, std::uint32_t(2));
  append(bad, std::uint32_t(12));
  bad += char(1 << 5);
  bad += char(9);
  EXPECT_NE(messageOf("bad.pcd", bad).find("corrupt"), std::string::npos);
}

TEST(CloudIo, PlyBinaryBigEndianAndAscii) {
  std::string b = "ply\nformat binary_big_endian 1.0\ncomment x\nelement vertex 3\n"
                  "property double x\nproperty float y\nproperty uchar r\nproperty float z\n"
                  "element face 0\nproperty list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < 3; ++i) {
    append(b, double(i), true);
    append(b, float(2 * i), true);
    append(b, std::uint8_t(9), true);
    append(b, -float(i) / 4, true);
  }
  expectRamp(parseCloud("b.ply", b), 3);
  const std::string a = "ply\r\nformat ascii 1.0\r\nelement vertex 2\r\nproperty float x\r\n"
                        "property float y\r\nproperty float z\r\nend_header\r\n0 0 0\r\n1 2 -0.25\r\n";
  expectRamp(parseCloud("a.ply", a), 2);
}

TEST(CloudIo, NonFinitePointsAreKeptWhenSomeAreFinite) {
  std::string s = pcdHeader("x y z", "4 4 4", "F F F", 2, "binary");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (float v : {nan, nan, nan, 1.f, 2.f, 3.f}) append(s, v);
  const PointArray p = parseCloud("n.pcd", s);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_TRUE(std::isnan(p.x[0]));
  EXPECT_EQ(p.z[1], 3.f);
}

TEST(CloudIo, LiesAreRefusedWithTheirReason) {
  std::string body;
  for (int i = 0; i < 300; ++i) append(body, float(i));  // 100 points
  largest_allocation = 0;
  EXPECT_NE(messageOf("l.pcd", pcdHeader("x y z", "4 4 4", "F F F", 50000000, "binary") + body)
                .find("truncated body"),
            std::string::npos);
  EXPECT_NE(messageOf("l.pcd", pcdHeader("x y z", "4 4 4", "F F F", 999999999, "binary") + body)
                .find("above the limit"),
            std::string::npos);
  std::string c = pcdHeader("x y z", "4 4 4", "F F F", 100000000, "binary_compressed");
  append(c, std::uint32_t(16));
  append(c, std::uint32_t(1200000000));
  c += std::string(16, '\0');
  EXPECT_NE(messageOf("c.pcd", c).find("compressed body declares"), std::string::npos);
  EXPECT_NE(messageOf("p.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 90000000\n"
                               "property float x\nproperty float y\nproperty float z\n"
                               "end_header\n" + body)
                .find("truncated body"),
            std::string::npos);
  // No allocation for what a file merely declares (50-100 million points, 1.2 GB compressed):
  // the largest single block is far below the smallest lie's 600 MB (the body is 1.2 kB).
  EXPECT_LT(largest_allocation.load(), std::size_t(1) << 20);
  EXPECT_NE(messageOf("h.pcd", "VERSION 0.7\nFIELDS x y z\n").find("before its DATA"),
            std::string::npos);
  EXPECT_NE(messageOf("w.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\n"
                               "POINTS 3\nDATA binary\n" + body)
                .find("WIDTH x HEIGHT = 2 but POINTS = 3"),
            std::string::npos);
  EXPECT_NE(messageOf("m.txt", body).find("unknown extension"), std::string::npos);
  EXPECT_NE(messageOf("e.ply", "").find("empty file"), std::string::npos);
  EXPECT_NE(messageOf("i.pcd", pcdHeader("x y z", "4 4 4", "I F F", 100, "binary") + body)
                .find("must be one float or double"),
            std::string::npos);
}

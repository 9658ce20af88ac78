#include "focal/io/mesh_io.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "focal/io/fields_io.h"
#include "test_meshes.h"

namespace fs = std::filesystem;
using focal::ExecutionScope;
using focal::Mesh;
using focal::RowMatrixX3d;
using focal::RowMatrixX3i;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------------
// Helpers

/// A fresh folder per test, removed afterwards.
class MeshIo : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::random_device rd;
    dir_ = fs::temp_directory_path() /
           ("focal_mesh_io_" + std::string(info->name()) + "_" + std::to_string(rd()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  [[nodiscard]] fs::path file(const std::string& name) const { return dir_ / name; }

  fs::path write(const std::string& name, const std::string& bytes) const {
    const fs::path p = file(name);
    std::ofstream out(p, std::ios::binary);
    out << bytes;
    return p;
  }

  [[nodiscard]] std::vector<std::string> folder_entries() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }

  fs::path dir_;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Runs `f`, expects an exception of type E whose message contains every one of `parts`.
template <class E>
void expect_error(const std::function<void()>& f, std::initializer_list<std::string> parts) {
  try {
    f();
    ADD_FAILURE() << "no exception thrown; expected one containing " << *parts.begin();
  } catch (const E& e) {
    const std::string message = e.what();
    for (const auto& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos)
          << "message \"" << message << "\" lacks \"" << part << "\"";
    }
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type: " << e.what();
  }
}

void expect_io_error(const fs::path& p, std::initializer_list<std::string> parts) {
  std::vector<std::string> all{p.string()};
  all.insert(all.end(), parts.begin(), parts.end());
  try {
    (void)focal::read_mesh(p);
    ADD_FAILURE() << "no exception reading " << p;
  } catch (const focal::IoError& e) {
    const std::string message = e.what();
    for (const auto& part : all) {
      EXPECT_NE(message.find(part), std::string::npos)
          << "message \"" << message << "\" lacks \"" << part << "\"";
    }
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type reading " << p << ": " << e.what();
  }
}

/// Exact equality, NaN equal to NaN and the sign of zero compared too.
void expect_same(const RowMatrixX3d& a, const RowMatrixX3d& b) {
  ASSERT_EQ(a.rows(), b.rows());
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const double x = a(i, c);
      const double y = b(i, c);
      if (std::isnan(x) || std::isnan(y)) {
        EXPECT_TRUE(std::isnan(x) && std::isnan(y)) << "row " << i << " col " << c;
      } else {
        EXPECT_EQ(x, y) << "row " << i << " col " << c;
        EXPECT_EQ(std::signbit(x), std::signbit(y)) << "row " << i << " col " << c;
      }
    }
  }
}

/// Equality up to a few rounding errors (for values the reader computes, such as normalised
/// averages), NaN equal to NaN.
void expect_close(const RowMatrixX3d& a, const RowMatrixX3d& b) {
  ASSERT_EQ(a.rows(), b.rows());
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    for (int c = 0; c < 3; ++c) {
      if (std::isnan(a(i, c)) || std::isnan(b(i, c))) {
        EXPECT_TRUE(std::isnan(a(i, c)) && std::isnan(b(i, c))) << "row " << i << " col " << c;
      } else {
        EXPECT_NEAR(a(i, c), b(i, c), 1e-15) << "row " << i << " col " << c;
      }
    }
  }
}

void expect_faces(const Mesh& m, std::initializer_list<std::array<int, 3>> faces,
                  std::initializer_list<int> sources) {
  ASSERT_EQ(m.F.rows(), static_cast<Eigen::Index>(faces.size()));
  ASSERT_EQ(m.face_source.size(), static_cast<Eigen::Index>(sources.size()));
  Eigen::Index f = 0;
  for (const auto& t : faces) {
    EXPECT_EQ(m.F(f, 0), t[0]) << "triangle " << f;
    EXPECT_EQ(m.F(f, 1), t[1]) << "triangle " << f;
    EXPECT_EQ(m.F(f, 2), t[2]) << "triangle " << f;
    ++f;
  }
  Eigen::Index s = 0;
  for (const int src : sources) EXPECT_EQ(m.face_source[s++], src) << "triangle " << s - 1;
}

focal::PlyWriteOptions ascii_options() {
  focal::PlyWriteOptions options;
  options.binary = false;
  return options;
}

RowMatrixX3d rows(std::initializer_list<std::array<double, 3>> values) {
  RowMatrixX3d m(static_cast<Eigen::Index>(values.size()), 3);
  Eigen::Index i = 0;
  for (const auto& r : values) {
    m.row(i++) << r[0], r[1], r[2];
  }
  return m;
}

/// A small mesh whose coordinates need all 17 significant digits, with a negative zero,
/// a subnormal-sized value, a huge one and a non-manifold edge (0-1 shared by three triangles).
Mesh sample_mesh(bool with_normals) {
  Mesh m;
  m.V = rows({{0.1, -2.5, 1e-300},
              {1.0 / 3.0, 2.0 / 3.0, 7.0},
              {-0.0, 5e10, 3.141592653589793},
              {1.0, 1.0, 1.0},
              {-1e-7, 123456.789, -0.30000000000000004}});
  m.F.resize(4, 3);
  m.F << 0, 1, 2, 0, 1, 3, 1, 0, 4, 2, 3, 4;
  m.face_source = Eigen::VectorXi::LinSpaced(4, 0, 3);
  if (with_normals) {
    m.N = rows({{0, 0, 1},
                {0.6, 0.8, 0},
                {-1, 0, 0},
                {0.5773502691896258, 0.5773502691896258, 0.5773502691896258},
                {0, -1, 0}});
  }
  return m;
}

void expect_same_mesh(const Mesh& expected, const Mesh& actual) {
  expect_same(expected.V, actual.V);
  ASSERT_EQ(expected.F.rows(), actual.F.rows());
  EXPECT_TRUE(expected.F == actual.F);
  EXPECT_TRUE(expected.face_source == actual.face_source);
  ASSERT_EQ(expected.has_normals(), actual.has_normals());
  if (expected.has_normals()) expect_same(expected.N, actual.N);
}

/// Binary data in either byte order, for hand-written PLY and STL files.
class Bytes {
 public:
  explicit Bytes(bool big_endian = false) : big_(big_endian) {}
  template <class T>
  Bytes& put(T value) {
    char b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    const bool host_big = std::endian::native == std::endian::big;
    if (big_ != host_big) std::reverse(b, b + sizeof(T));
    data.append(b, sizeof(T));
    return *this;
  }
  Bytes& text(std::string_view s) {
    data += s;
    return *this;
  }
  std::string data;

 private:
  bool big_;
};

// ---------------------------------------------------------------------------------------------
// Format dispatch

TEST_F(MeshIo, FormatFromExtensionIsCaseInsensitive) {
  EXPECT_EQ(focal::mesh_format_from_path("a/b.OBJ"), focal::MeshFormat::obj);
  EXPECT_EQ(focal::mesh_format_from_path("b.Ply"), focal::MeshFormat::ply);
  EXPECT_EQ(focal::mesh_format_from_path("b.off"), focal::MeshFormat::off);
  EXPECT_EQ(focal::mesh_format_from_path("b.stl"), focal::MeshFormat::stl);
  EXPECT_EQ(focal::mesh_format_from_path("cloud.XYZ"), focal::MeshFormat::xyz);
  EXPECT_EQ(focal::mesh_format_from_path("oni.pwn"), focal::MeshFormat::xyz);  // CGAL's data
  expect_error<focal::IoError>([] { (void)focal::mesh_format_from_path("dir/mesh.abc"); },
                               {"dir/mesh.abc", ".abc"});
  expect_error<focal::IoError>([] { (void)focal::mesh_format_from_path("noext"); }, {"noext"});
}

TEST_F(MeshIo, ReadErrorsNameThePath) {
  const fs::path unknown = write("mesh.abc", "v 0 0 0\n");
  expect_io_error(unknown, {"unknown mesh format"});
  expect_io_error(file("missing.ply"), {"no such file"});
  fs::create_directories(file("folder.obj"));
  expect_io_error(file("folder.obj"), {"directory"});
  // A path through a regular file cannot exist.
  const fs::path through = write("plain.txt", "x") / "mesh.off";
  expect_io_error(through, {});
}

TEST_F(MeshIo, UnreadableFileIsAnIoError) {
  const fs::path p = write("locked.obj", "v 0 0 0\n");
  fs::permissions(p, fs::perms::none);
  if (std::ifstream(p).good()) {
    fs::permissions(p, fs::perms::owner_all);
    GTEST_SKIP() << "running with privileges that read any file";
  }
  expect_io_error(p, {"cannot open"});
  fs::permissions(p, fs::perms::owner_all);
}

// A path that no user can open, root included (CI runs as root, where the permission test above
// skips): a regular file used as a folder (ENOTDIR).
TEST_F(MeshIo, PathThroughAFileIsAnIoError) {
  const fs::path plain = write("plain.obj", "v 0 0 0\n");
  expect_io_error(plain / "inner.obj", {"inner.obj"});
}

// ---------------------------------------------------------------------------------------------
// Round trips through the writers

TEST_F(MeshIo, PlyBinaryRoundTripIsExact) {
  for (const bool normals : {false, true}) {
    const Mesh m = sample_mesh(normals);
    const fs::path p = file(normals ? "n.ply" : "plain.ply");
    focal::write_ply(p, m);
    EXPECT_NE(slurp(p).find("format binary_little_endian 1.0"), std::string::npos);
    expect_same_mesh(m, focal::read_mesh(p));
  }
}

/// n vertices with normals (signed zeros and subnormal-sized components among them) and n
/// triangles over consecutive vertices: every number a writer has to keep exact.
Mesh strip_mesh(int n) {
  Mesh m;
  m.V.resize(n, 3);
  m.N.resize(n, 3);
  m.F.resize(n, 3);
  for (int i = 0; i < n; ++i) {
    m.V.row(i) << 0.001 * i, std::sin(0.37 * i), 1.0 / (i + 1);
    m.N.row(i) << 0.0, std::cos(0.37 * i), i % 7 == 0 ? -0.0 : 1e-300 * i;
    m.F.row(i) << i, (i + 1) % n, (i + 2) % n;
  }
  return m;
}

TEST_F(MeshIo, FilesBelowAndAboveTheMappedSizeReadTheSame) {
  // The readers map a file of 1 MiB or more and read a smaller one into a buffer: a binary PLY
  // with normals (48 bytes a vertex, 13 a face, and the header) on each side of 1 MiB, an OBJ
  // above it, all exact; a truncated mapped file is an IoError, not a read past its end.
  for (const int n : {15000, 25000}) {
    SCOPED_TRACE("vertices " + std::to_string(n));
    Mesh m = strip_mesh(n);
    m.face_source = Eigen::VectorXi::LinSpaced(n, 0, n - 1);  // each triangle its own polygon
    const fs::path ply = file("m.ply");
    focal::write_ply(ply, m);
    EXPECT_EQ(fs::file_size(ply) >= (1u << 20), n == 25000);
    expect_same_mesh(m, focal::read_mesh(ply));
    const fs::path obj = file("m.obj");
    focal::write_obj(obj, m);
    expect_same_mesh(m, focal::read_mesh(obj));
    fs::resize_file(ply, fs::file_size(ply) - 7);
    EXPECT_THROW((void)focal::read_mesh(ply), focal::IoError);
  }
}

TEST_F(MeshIo, TextWritersGiveTheSameBytesOnAnyThreadCount) {
  // 40,000 vertices and faces: more lines than one batch of the parallel blocks (32,768), so
  // blocks, batches and the header before them all meet.
  const int n = 40000;
  const Mesh m = strip_mesh(n);
  const std::vector<focal::CsvColumn> columns{{"x", Eigen::VectorXd(m.V.col(0))},
                                              {"word", std::vector<std::string>(n, "a,b")}};
  for (const focal::Precision precision : {focal::Precision::float64, focal::Precision::float32}) {
    std::vector<std::string> first;
    for (const int threads : {1, 2, 3}) {
      const ExecutionScope scope({.threads = threads});
      SCOPED_TRACE("threads " + std::to_string(threads));
      const focal::WriteOptions o{.precision = precision};
      focal::write_obj(file("t.obj"), m, o);
      focal::write_off(file("t.off"), m, o);
      focal::write_xyz(file("t.xyz"), m, o);
      focal::write_ply(file("t.ply"), m, {},
                       {.binary = false, .comments = {}, .precision = precision});
      focal::write_csv(file("t.csv"), columns, o);
      const std::vector<std::string> bytes{slurp(file("t.obj")), slurp(file("t.off")),
                                           slurp(file("t.xyz")), slurp(file("t.ply")),
                                           slurp(file("t.csv"))};
      if (first.empty()) first = bytes;
      for (std::size_t k = 0; k < bytes.size(); ++k) EXPECT_TRUE(bytes[k] == first[k]) << k;
    }
    // And what the writers wrote is the mesh (OBJ as a check that the lines are complete).
    const Mesh back = focal::read_mesh(file("t.obj"));
    EXPECT_EQ(back.V.rows(), n);
    EXPECT_EQ(back.F.rows(), n);
  }
}

TEST_F(MeshIo, PlyAsciiRoundTripIsExact) {
  for (const bool normals : {false, true}) {
    const Mesh m = sample_mesh(normals);
    const fs::path p = file("ascii.ply");
    focal::write_ply(p, m, {}, {.binary = false, .comments = {"made by a test"}});
    const std::string text = slurp(p);
    EXPECT_NE(text.find("format ascii 1.0\ncomment made by a test\n"), std::string::npos);
    EXPECT_NE(text.find("\n0.1 -2.5 1e-300"), std::string::npos);
    expect_same_mesh(m, focal::read_mesh(p));
  }
}

TEST_F(MeshIo, ObjRoundTripIsExact) {
  for (const bool normals : {false, true}) {
    const Mesh m = sample_mesh(normals);
    const fs::path p = file("m.obj");
    focal::write_obj(p, m);
    const std::string text = slurp(p);
    EXPECT_EQ(text.rfind("v 0.1 -2.5 1e-300\n", 0), 0u);
    EXPECT_NE(text.find(normals ? "f 1//1 2//2 3//3\n" : "f 1 2 3\n"), std::string::npos);
    expect_same_mesh(m, focal::read_mesh(p));
  }
}

TEST_F(MeshIo, OffRoundTripIsExact) {
  for (const bool normals : {false, true}) {
    const Mesh m = sample_mesh(normals);
    const fs::path p = file("m.off");
    focal::write_off(p, m);
    EXPECT_EQ(slurp(p).rfind(normals ? "NOFF\n5 4 0\n" : "OFF\n5 4 0\n", 0), 0u);
    expect_same_mesh(m, focal::read_mesh(p));
  }
}

TEST_F(MeshIo, WriteMeshDispatchesOnExtension) {
  const Mesh m = sample_mesh(true);
  for (const char* name : {"a.ply", "a.OBJ", "a.off"}) {
    focal::write_mesh(file(name), m);
    expect_same_mesh(m, focal::read_mesh(file(name)));
  }
  EXPECT_EQ(slurp(file("a.ply")).substr(0, 36), "ply\nformat binary_little_endian 1.0\n");
  expect_error<focal::IoError>([&] { focal::write_mesh(file("a.stl"), m); },
                               {file("a.stl").string(), "STL"});
  expect_error<focal::IoError>([&] { focal::write_mesh(file("a.vtk"), m); },
                               {file("a.vtk").string()});
  EXPECT_FALSE(fs::exists(file("a.stl")));
}

TEST_F(MeshIo, NanAndInfinityAreReadAsIs) {
  Mesh m;
  m.V = rows({{kNaN, 1, 2}, {kInf, -kInf, 0}, {0, 0, 0}});
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  m.face_source = Eigen::VectorXi::Zero(1);
  for (const char* name : {"nan.obj", "nan.off", "nan.ply"}) {
    focal::write_mesh(file(name), m);
    expect_same_mesh(m, focal::read_mesh(file(name)));
  }
  focal::write_ply(file("nan_ascii.ply"), m, {}, ascii_options());
  EXPECT_NE(slurp(file("nan_ascii.ply")).find("\nnan 1 2\ninf -inf 0\n"), std::string::npos);
  expect_same_mesh(m, focal::read_mesh(file("nan_ascii.ply")));
  // Other spellings writers use.
  const Mesh r = focal::read_mesh(write("spell.obj", "v NaN +Inf -infinity\nv +1.5e+00 0 0\n"));
  EXPECT_TRUE(std::isnan(r.V(0, 0)));
  EXPECT_EQ(r.V(0, 1), kInf);
  EXPECT_EQ(r.V(0, 2), -kInf);
  EXPECT_EQ(r.V(1, 0), 1.5);
}

TEST_F(MeshIo, VertexOrderIsPreservedInEveryFormat) {
  // Coordinates in a scrambled order with duplicates and unreferenced vertices: any reader that
  // sorts, merges or drops vertices changes these rows.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-1, 1);
  Mesh m;
  m.V.resize(200, 3);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    m.V.row(i) << coord(rng), coord(rng), coord(rng);
  }
  m.V.row(10) = m.V.row(3);  // a duplicate position that must not be welded
  m.F.resize(150, 3);
  std::uniform_int_distribution<int> index(0, 179);  // vertices 180..199 are in no face
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    m.F.row(f) << index(rng), index(rng), index(rng);
  }
  m.F.row(5) = m.F.row(4);  // a duplicate face that must not be dropped
  m.face_source = Eigen::VectorXi::LinSpaced(150, 0, 149);
  for (const char* name : {"o.ply", "o.obj", "o.off"}) {
    focal::write_mesh(file(name), m);
    expect_same_mesh(m, focal::read_mesh(file(name)));
  }
  focal::write_ply(file("o_ascii.ply"), m, {}, ascii_options());
  expect_same_mesh(m, focal::read_mesh(file("o_ascii.ply")));
}

// ---------------------------------------------------------------------------------------------
// PLY reading

/// The same mesh in three encodings: properties in an unusual order, extra vertex properties
/// (including a list), an `edge` element between vertex and face, extra face properties, a quad.
std::string rich_ply(const std::string& encoding) {
  std::string h = "ply\r\nformat " + encoding + " 1.0\n" +
                  "comment properties out of the usual order\n"
                  "obj_info generated by hand\n"
                  "element vertex 4\n"
                  "property float z\n"
                  "property uchar red\n"
                  "property double x\n"
                  "property list uchar int64 ignored_list\n"
                  "property float32 nz\n"
                  "property float y\n"
                  "property float ny\n"
                  "property float nx\n"
                  "element edge 2\n"
                  "property int vertex1\n"
                  "property int vertex2\n"
                  "element face 2\n"
                  "property uchar flags\n"
                  "property list uchar uint vertex_indices\n"
                  "property list int float texcoord\n"
                  "end_header\n";
  // int64 (meshio's) is read too (PlyHeaderErrors); the file here keeps Turk's int.
  h.replace(h.find("int64"), 5, "int");
  const double xyz[4][3] = {{0.5, 1.25, -2}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const float n[4][3] = {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}, {0, 0, -1}};
  if (encoding == "ascii") {
    std::ostringstream s;
    s << h;
    for (int i = 0; i < 4; ++i) {
      s << xyz[i][2] << " 200 " << xyz[i][0] << " 2 7 8 " << n[i][2] << " " << xyz[i][1] << " "
        << n[i][1] << " " << n[i][0] << "\n";
    }
    s << "0 1\n\n2 3\n";  // edges; a blank line is tolerated
    s << "9 4 0 1 2 3 2 0.5 0.5\n";
    s << "1 3 3 2 1 0\n";
    return s.str();
  }
  Bytes b(encoding == "binary_big_endian");
  b.text(h);
  for (int i = 0; i < 4; ++i) {
    b.put(static_cast<float>(xyz[i][2])).put(std::uint8_t{200}).put(xyz[i][0]);
    b.put(std::uint8_t{2}).put(std::int32_t{7}).put(std::int32_t{8});
    b.put(n[i][2]).put(static_cast<float>(xyz[i][1])).put(n[i][1]).put(n[i][0]);
  }
  b.put(std::int32_t{0}).put(std::int32_t{1}).put(std::int32_t{2}).put(std::int32_t{3});
  b.put(std::uint8_t{9}).put(std::uint8_t{4});
  for (std::uint32_t v : {0u, 1u, 2u, 3u}) b.put(v);
  b.put(std::int32_t{2}).put(0.5f).put(0.5f);
  b.put(std::uint8_t{1}).put(std::uint8_t{3});
  for (std::uint32_t v : {3u, 2u, 1u}) b.put(v);
  b.put(std::int32_t{0});
  return b.data;
}

TEST_F(MeshIo, PlyExtraPropertiesAndElementsAreSkippedInEveryEncoding) {
  for (const char* encoding : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    SCOPED_TRACE(encoding);
    const Mesh m = focal::read_mesh(write("rich.ply", rich_ply(encoding)));
    expect_same(m.V, rows({{0.5, 1.25, -2}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}));
    ASSERT_TRUE(m.has_normals());
    expect_same(m.N, rows({{0, 0, 1}, {0, 1, 0}, {1, 0, 0}, {0, 0, -1}}));
    // The quad is fanned from its first corner; both halves point back to polygon 0.
    expect_faces(m, {{0, 1, 2}, {0, 2, 3}, {3, 2, 1}}, {0, 0, 1});
  }
}

TEST_F(MeshIo, PlyEveryScalarTypeAndAliasIsSkippedCorrectly) {
  const char* types[] = {"char",   "uchar",   "short",  "ushort", "int",    "uint",
                         "float",  "int8",    "uint8",  "int16",  "uint16", "int32",
                         "uint32", "float32", "double", "float64"};
  for (const bool big : {false, true}) {
    std::string h = std::string("ply\nformat ") +
                    (big ? "binary_big_endian" : "binary_little_endian") +
                    " 1.0\nelement vertex 2\n";
    for (const char* t : types) h += std::string("property ") + t + " p_" + t + "\n";
    h += "property double x\nproperty float y\nproperty double z\n";
    h += "element face 1\nproperty list ushort short vertex_index\nend_header\n";
    Bytes b(big);
    b.text(h);
    for (int v = 0; v < 2; ++v) {
      b.put(std::int8_t{-1}).put(std::uint8_t{255}).put(std::int16_t{-2}).put(std::uint16_t{3});
      b.put(std::int32_t{-4}).put(std::uint32_t{5}).put(6.5f).put(std::int8_t{7});
      b.put(std::uint8_t{8}).put(std::int16_t{9}).put(std::uint16_t{10}).put(std::int32_t{11});
      b.put(std::uint32_t{12}).put(13.5f).put(14.5).put(15.5);
      b.put(v + 0.25).put(static_cast<float>(-v)).put(1e100 * v);
    }
    b.put(std::uint16_t{3}).put(std::int16_t{1}).put(std::int16_t{0}).put(std::int16_t{1});
    const Mesh m = focal::read_mesh(write("types.ply", b.data));
    expect_same(m.V, rows({{0.25, 0, 0}, {1.25, -1, 1e100}}));
    EXPECT_FALSE(m.has_normals());
    expect_faces(m, {{1, 0, 1}}, {0});
  }
}

TEST_F(MeshIo, PlyWithoutFacesIsAPointCloud) {
  const Mesh m = focal::read_mesh(
      write("points.ply",
            "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\n"
            "property double z\nend_header\n1 2 3\n4 5 6\n"));
  expect_same(m.V, rows({{1, 2, 3}, {4, 5, 6}}));
  EXPECT_EQ(m.F.rows(), 0);
  EXPECT_EQ(m.face_source.size(), 0);
}

// x y z r g b without a header, as photogrammetry tools and CloudCompare write clouds: read as
// normals, the colours would pick the side of every estimated normal. An error asking for a
// header, and the header read; unit normals of one sign (a plane's) and zero rows stay normals.
TEST_F(MeshIo, PointTextWhoseLastColumnsLookLikeColoursAsksForAHeader) {
  expect_io_error(write("rgb.xyz", "0 0 0 200 100 50\n1 0 0 0 255 3\n0 1 0 9 9 9\n"),
                  {"rgb.xyz", "look like colours", "'200 100 50'", "'x y z r g b'"});
  expect_io_error(write("unit.xyz", "0 0 0 0.2 0.5 0.1\n1 0 0 0.9 0.9 0.9\n0 1 0 0 0 1\n"),
                  {"unit.xyz", "look like colours"});
  const Mesh named =
      focal::read_mesh(write("rgb.txt", "//X,Y,Z,R,G,B\n0,0,0,200,100,50\n1,2,3,0,0,0\n"));
  expect_same(named.V, rows({{0, 0, 0}, {1, 2, 3}}));
  EXPECT_FALSE(named.has_normals());
  const Mesh plane =
      focal::read_mesh(write("plane.xyz", "0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 0\n"));
  expect_same(plane.N, rows({{0, 0, 1}, {0, 0, 1}, {0, 0, 0}}));
  const Mesh mixed = focal::read_mesh(write("mixed.xyz", "0 0 0 2 0 0\n1 0 0 0 -3 0\n"));
  EXPECT_TRUE(mixed.has_normals());  // a negative value: not colours, kept as written
}

// Open3D's extensions say what six columns hold: .xyzn normals even where they would look like
// colours, .xyzrgb colours (skipped), and a file of another width is an error; focal writes .xyzn
// but not .xyzrgb (its normals would read back as colours).
TEST_F(MeshIo, Open3dExtensionsSayWhatSixColumnsHold) {
  EXPECT_EQ(focal::mesh_format_from_path("a.XYZN"), focal::MeshFormat::xyz);
  EXPECT_EQ(focal::mesh_format_from_path("a.xyzrgb"), focal::MeshFormat::xyz);
  const Mesh n = focal::read_mesh(write("n.xyzn", "0 0 0 0.2 0.5 0.1\n1 2 3 2 0 0\n"));
  expect_same(n.N, rows({{0.2, 0.5, 0.1}, {2, 0, 0}}));
  const Mesh c = focal::read_mesh(write("c.xyzrgb", "0 0 0 0 0 1\n1 2 3 0.5 0.5 0.5\n"));
  expect_same(c.V, rows({{0, 0, 0}, {1, 2, 3}}));
  EXPECT_FALSE(c.has_normals());
  expect_io_error(write("short.xyzn", "0 0 0\n"), {"line 1", "expected 6 numbers (x y z nx ny nz"});
  expect_io_error(write("long.xyzrgb", "0 0 0 1 1 1 1\n"), {"expected 6 numbers (x y z r g b"});
  Mesh cloud;
  cloud.V = rows({{0, 0, 0}});
  cloud.N = rows({{0, 0, 1}});
  cloud.F.resize(0, 3);
  focal::write_mesh(file("w.xyzn"), cloud);
  expect_same(focal::read_mesh(file("w.xyzn")).N, cloud.N);
  expect_error<focal::IoError>([&] { focal::write_mesh(file("w.xyzrgb"), cloud); },
                               {"w.xyzrgb", "writing .xyzrgb is not supported"});
  EXPECT_FALSE(fs::exists(file("w.xyzrgb")));
}

// PCL writes its normals as normal_x normal_y normal_z (with a curvature beside them).
TEST_F(MeshIo, PclNormalNamesAreNormals) {
  const Mesh ply = focal::read_mesh(
      write("pcl.ply",
            "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
            "property float z\nproperty float normal_x\nproperty float normal_y\n"
            "property float normal_z\nproperty float curvature\nend_header\n"
            "1 2 3 0 0 1 0.5\n4 5 6 0 -1 0 0.25\n"));
  expect_same(ply.N, rows({{0, 0, 1}, {0, -1, 0}}));
  const Mesh csv = focal::read_mesh(
      write("pcl.csv", "x,y,z,curvature,normal_x,normal_y,normal_z\n1,2,3,9,0,0,1\n"));
  expect_same(csv.V, rows({{1, 2, 3}}));
  expect_same(csv.N, rows({{0, 0, 1}}));
}

// A header may name its normal's columns in any order; a row shorter than the last column named
// is an error (the fuzzer found it read past the row when ny came after nz).
TEST_F(MeshIo, PointHeaderInAnyOrderNeedsEveryColumnItNames) {
  const Mesh m = focal::read_mesh(write("order.csv", "nz,x,ny,y,nx,z\n1,2,0,3,0,4\n"));
  expect_same(m.V, rows({{2, 3, 4}}));
  expect_same(m.N, rows({{0, 0, 1}}));
  expect_io_error(write("short.csv", "x,y,z,nx,nz,nx,ny,nz\n0,0,1,0,0,1\n"),
                  {"line 2", "expected at least 7 numbers", "found 6"});
}

TEST_F(MeshIo, PlyWritesExtraVertexPropertiesWithTheirTypes) {
  const Mesh m = sample_mesh(false);
  std::vector<focal::VertexProperty> props(4);
  props[0] = {"k1", Eigen::VectorXd::LinSpaced(5, 0.5, 2.5), focal::PropertyType::float64};
  props[1] = {"quality", Eigen::VectorXd::Constant(5, 0.1), focal::PropertyType::float32};
  props[2] = {"class", Eigen::VectorXd::LinSpaced(5, 0, 4), focal::PropertyType::uint8};
  props[3] = {"label", Eigen::VectorXd::Constant(5, -7), focal::PropertyType::int32};
  props[0].values[1] = kNaN;

  focal::write_ply(file("p.ply"), m, props, ascii_options());
  const std::string text = slurp(file("p.ply"));
  EXPECT_NE(text.find("property double z\nproperty double k1\nproperty float quality\n"
                      "property uchar class\nproperty int label\nelement face 4\n"
                      "property list uchar int vertex_indices\nend_header\n"
                      "0.1 -2.5 1e-300 0.5 0.1 0 -7\n"
                      "0.3333333333333333 0.6666666666666666 7 nan 0.1 1 -7\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("\n3 2 3 4\n"), std::string::npos);
  // The extra properties are skipped when reading back; geometry is intact.
  expect_same_mesh(m, focal::read_mesh(file("p.ply")));

  focal::write_ply(file("pb.ply"), m, props);
  const std::string bin = slurp(file("pb.ply"));
  const std::size_t body = bin.find("end_header\n") + 11;
  // Per vertex 3 doubles + double + float + uchar + int; per face uchar + 3 ints.
  EXPECT_EQ(bin.size() - body, 5u * (24 + 8 + 4 + 1 + 4) + 4u * 13);
  double k1 = 0;
  std::memcpy(&k1, bin.data() + body + 24, 8);
  EXPECT_EQ(k1, 0.5);
  std::uint8_t cls = 0;
  std::memcpy(&cls, bin.data() + body + 41 + 36, 1);  // vertex 1, after 3+1 doubles and a float
  EXPECT_EQ(cls, 1);
  expect_same_mesh(m, focal::read_mesh(file("pb.ply")));
}

TEST_F(MeshIo, PlyPropertyValidation) {
  const Mesh m = sample_mesh(true);
  const auto bad = [&](focal::VertexProperty p, const std::string& part) {
    std::vector<focal::VertexProperty> props{std::move(p)};
    expect_error<focal::InvalidInput>([&] { focal::write_ply(file("bad.ply"), m, props); },
                                      {file("bad.ply").string(), part});
    EXPECT_FALSE(fs::exists(file("bad.ply")));
  };
  bad({"k1", Eigen::VectorXd::Zero(4), focal::PropertyType::float32}, "has 4 values");
  bad({"has space", Eigen::VectorXd::Zero(5), focal::PropertyType::float32}, "has space");
  bad({"nx", Eigen::VectorXd::Zero(5), focal::PropertyType::float32}, "used twice");
  bad({"c", Eigen::VectorXd::Constant(5, 256), focal::PropertyType::uint8}, "uchar");
  bad({"c", Eigen::VectorXd::Constant(5, 0.5), focal::PropertyType::int32}, "int");
  bad({"c", Eigen::VectorXd::Constant(5, kNaN), focal::PropertyType::int32}, "int");
  expect_error<focal::InvalidInput>(
      [&] { focal::write_ply(file("bad.ply"), m, {}, {.comments = {"two\nlines"}}); }, {"comment"});
  Mesh broken = m;
  broken.F(0, 0) = 5;
  expect_error<focal::InvalidInput>([&] { focal::write_ply(file("bad.ply"), broken); },
                                    {"face 0", "vertex 5"});
  EXPECT_FALSE(fs::exists(file("bad.ply")));
}

// PLY errors ----------------------------------------------------------------------------------

const std::string kAsciiHeader =
    "ply\n"                                     // 1
    "format ascii 1.0\n"                        // 2
    "element vertex 3\n"                        // 3
    "property float x\n"                        // 4
    "property float y\n"                        // 5
    "property float z\n"                        // 6
    "element face 1\n"                          // 7
    "property list uchar int vertex_indices\n"  // 8
    "end_header\n";                             // 9

TEST_F(MeshIo, PlyAsciiErrorsNameLineAndElement) {
  expect_io_error(write("short.ply", kAsciiHeader + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n"),
                  {"line 11", "vertex 1", "expected 3 values, got 2"});
  expect_io_error(write("long.ply", kAsciiHeader + "0 0 0\n1 0 0 4\n0 1 0\n3 0 1 2\n"),
                  {"line 11", "expected 3 values, got 4"});
  expect_io_error(write("word.ply", kAsciiHeader + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n"),
                  {"line 11", "'zero' is not a number"});
  expect_io_error(write("range.ply", kAsciiHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
                  {"line 13", "face 0 refers to vertex 7 but there are 3 vertices"});
  expect_io_error(write("negative.ply", kAsciiHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"),
                  {"line 13", "face 0 refers to vertex -1"});
  expect_io_error(write("two.ply", kAsciiHeader + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
                  {"line 13", "face 0 has 2 vertices"});
  expect_io_error(write("list.ply", kAsciiHeader + "0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n"),
                  {"line 13", "expected 5 values, got 4"});
  expect_io_error(write("ends.ply", kAsciiHeader + "0 0 0\n1 0 0\n"),
                  {"file ends inside vertex 2 of 3"});
  expect_io_error(write("huge.ply",
                        "ply\nformat ascii 1.0\nelement vertex 1000000000000\n"
                        "property float x\nproperty float y\nproperty float z\n"
                        "end_header\n0 0 0\n"),
                  {"1000000000000 vertex elements"});
}

TEST_F(MeshIo, PlyHeaderErrors) {
  expect_io_error(write("magic.ply", "plyx\nformat ascii 1.0\nend_header\n"), {"not a PLY file"});
  expect_io_error(write("noend.ply", "ply\nformat ascii 1.0\nelement vertex 0\n"), {"end_header"});
  expect_io_error(write("format.ply", "ply\nformat binary 1.0\nend_header\n"),
                  {"line 2", "unknown format"});
  expect_io_error(write("type.ply",
                        "ply\nformat ascii 1.0\nelement vertex 1\n"
                        "property long x\nend_header\n"),
                  {"line 4", "unknown property type 'long'"});
  // A list of int64 (meshio writes them) is skipped like any other list.
  std::string rich64 = rich_ply("ascii");
  rich64.replace(rich64.find("uchar int ignored"), 9, "uchar int64");
  expect_same_mesh(focal::read_mesh(write("rich.ply", rich_ply("ascii"))),
                   focal::read_mesh(write("rich64.ply", rich64)));
  expect_io_error(write("nox.ply",
                        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float y\n"
                        "end_header\n0\n"),
                  {"no scalar property 'x'"});
  expect_io_error(write("novertex.ply", "ply\nformat ascii 1.0\nend_header\n"),
                  {"no vertex element"});
  expect_io_error(write("nolist.ply",
                        "ply\nformat ascii 1.0\nelement vertex 0\n"
                        "property float x\nproperty float y\nproperty float z\n"
                        "element face 0\nproperty int vertex_indices\n"
                        "end_header\n"),
                  {"is not a list"});
  expect_io_error(write("keyword.ply", "ply\nformat ascii 1.0\nelements vertex 0\nend_header\n"),
                  {"line 3", "elements"});
  expect_io_error(write("floatcount.ply",
                        "ply\nformat ascii 1.0\nelement face 0\n"
                        "property list float int vertex_indices\nend_header\n"),
                  {"line 4", "count type"});
}

std::string binary_header(std::uint64_t vertices, std::uint64_t faces) {
  return "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
         std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

TEST_F(MeshIo, PlyBinaryErrorsNameByteOffsetAndElement) {
  const std::string header = binary_header(100, 1);
  Bytes b;
  b.text(header);
  for (int i = 0; i < 17 * 3 + 2; ++i) b.put(1.0f);  // vertex 17 has only 2 of its 3 floats
  expect_io_error(write("trunc.ply", b.data),
                  {"byte offset " + std::to_string(header.size() + 17 * 12),
                   "file ends inside vertex 17 of 100"});

  // Claims 1e12 vertices: rejected from the file size, before anything is allocated.
  expect_io_error(write("huge.ply", binary_header(1000000000000ull, 0) + std::string(64, '\0')),
                  {"file ends inside vertex 5 of 1000000000000"});
  // Variable-size elements: 1e12 faces of at least 1 byte each cannot fit either.
  expect_io_error(write("hugefaces.ply", binary_header(0, 1000000000000ull) + "abc"),
                  {"1000000000000 face elements"});

  Bytes f;
  f.text(binary_header(3, 2));
  for (int i = 0; i < 9; ++i) f.put(0.0f);
  f.put(std::uint8_t{3}).put(0).put(1).put(2);
  const std::size_t face1 = f.data.size();
  f.put(std::uint8_t{3}).put(0).put(1);
  expect_io_error(write("tface.ply", f.data),
                  {"byte offset " + std::to_string(face1), "file ends inside face 1 of 2"});
  f.put(2);
  const std::string range = f.data;
  std::string bad_range = range;
  bad_range[bad_range.size() - 4] = 9;
  expect_io_error(write("brange.ply", bad_range),
                  {"byte offset " + std::to_string(face1),
                   "face 1 refers to vertex 9 but there are 3 vertices"});
  std::string two = range;
  two[face1] = 2;
  expect_io_error(write("btwo.ply", two), {"face 1 has 2 vertices"});
  EXPECT_NO_THROW((void)focal::read_mesh(write("bok.ply", range)));
}

// ---------------------------------------------------------------------------------------------
// OBJ reading

TEST_F(MeshIo, ObjPolygonsAreFannedWithFaceSource) {
  const Mesh m = focal::read_mesh(write("poly.obj",
                                        "# a pentagon, a triangle and a quad\n"
                                        "mtllib none.mtl\no thing\ng group\ns 1\nusemtl red\n"
                                        "v 0 0 0\nv 1 0 0 1.0\nv 2 1 0 0.5 0.5 0.5\nv 1 2 0\n"
                                        "v 0 1 0  # trailing comment\n"
                                        "vt 0 0\nl 1 2\n"
                                        "f 1 2 3 4 5\n"
                                        "f 5/1 4/1 3/1\n"
                                        "\n\tf 1 2 4 5\r\n"));
  expect_same(m.V, rows({{0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {1, 2, 0}, {0, 1, 0}}));
  expect_faces(m, {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {4, 3, 2}, {0, 1, 3}, {0, 3, 4}},
               {0, 0, 0, 1, 2, 2});
  EXPECT_FALSE(m.has_normals());
}

TEST_F(MeshIo, ObjNormalsFromEveryCornerForm) {
  const Mesh m = focal::read_mesh(write("n.obj",
                                        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 5 5 5\n"
                                        "vt 0 0\nvt 1 0\n"
                                        "vn 0 0 1\nvn 1 0 0\nvn 0 0 2\n"
                                        "f 1//1 2//1 3//1\n"     // v//vn
                                        "f 2/1/3 4/2/3 3/1/1\n"  // v/vt/vn
                                        "f 1//2 3//1 4//3\n"     // v 1 with a second normal
                                        "f 5 1 2\n"));           // v 5 has no normal
  ASSERT_TRUE(m.has_normals());
  const double s = std::sqrt(0.5);
  // v1: vn1 and vn2 -> normalised average. v2: vn1 and vn3 -> (0,0,3)/3. v3: vn1 only.
  // v4: vn3 only, kept as written. v5: never with a normal -> NaN.
  expect_close(m.N, rows({{s, 0, s}, {0, 0, 1}, {0, 0, 1}, {0, 0, 2}, {kNaN, kNaN, kNaN}}));
  // Distinct normals count once each however often they are referenced.
  const Mesh twice = focal::read_mesh(write("twice.obj",
                                            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 1 0 0\n"
                                            "f 1//1 2//1 3//1\nf 1//1 3//1 2//1\n"
                                            "f 1//2 2//1 3//1\n"));
  EXPECT_DOUBLE_EQ(twice.N(0, 0), s);
  EXPECT_DOUBLE_EQ(twice.N(0, 2), s);
  // Opposite normals cancel: no direction, NaN rather than a made-up one.
  const Mesh cancel = focal::read_mesh(write("cancel.obj",
                                             "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 -1\n"
                                             "f 1//1 2//1 3//1\nf 1//2 3//2 2//2\n"));
  EXPECT_TRUE(cancel.N.row(0).array().isNaN().all());
  // vn lines that no face references give no normals, unless the file is a point cloud (no
  // faces) with one vn per v: then they pair in order (docs/POINTS.md).
  const Mesh unused = focal::read_mesh(write("unused.obj", "v 0 0 0\nv 1 0 0\nvn 0 0 1\n"));
  EXPECT_FALSE(unused.has_normals());
  const Mesh cloud = focal::read_mesh(write("cloud.obj", "v 0 0 0\nv 1 0 0\nvn 0 0 1\nvn 0 1 0\n"));
  ASSERT_TRUE(cloud.has_normals());
  EXPECT_EQ(cloud.N(1, 1), 1.0);
}

TEST_F(MeshIo, ObjNegativeIndicesAreRelative) {
  const Mesh m = focal::read_mesh(write("rel.obj",
                                        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\n"
                                        "f -3//-1 -2//-1 -1//-1\n"
                                        "v 1 1 0\nvn 0 1 0\nvt 0 0\n"
                                        "f -1/-1/-1 3/1/2 -3/-1/-2\n"));
  expect_faces(m, {{0, 1, 2}, {3, 2, 1}}, {0, 1});
  // Vertex 3 (0-based 2) is referenced with vn 1 and vn 2.
  const double s = std::sqrt(0.5);
  expect_close(m.N, rows({{0, 0, 1}, {0, 0, 1}, {0, s, s}, {0, 1, 0}}));
}

TEST_F(MeshIo, ObjErrorsNameLineAndFace) {
  expect_io_error(write("v2.obj", "v 0 0 0\n# comment\nv 1 0\n"),
                  {"line 3", "expected 3 coordinates, got 2"});
  expect_io_error(write("vn2.obj", "vn 0 0\n"), {"line 1", "expected 3 normal components"});
  expect_io_error(write("nan.obj", "v 0 0 zero\n"), {"line 1", "'zero' is not a number"});
  expect_io_error(write("f2.obj", "v 0 0 0\nv 1 0 0\nf 1 2 1\nf 1 2\n"),
                  {"line 4", "face 1 has 2 vertices"});
  expect_io_error(write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n"),
                  {"line 5", "face 1 refers to vertex 4 but there are 3 vertices"});
  expect_io_error(write("nrange.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n"),
                  {"line 5", "face 0 refers to normal 2 but there are 1 normals"});
  expect_io_error(write("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
                  {"line 4", "'0' is not a valid vertex index"});
  expect_io_error(write("rel.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n"),
                  {"line 4", "face 0", "relative vertex index -4"});
  expect_io_error(write("vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/x 2/1 3/1\n"),
                  {"line 5", "'x' is not a valid texture coordinate index"});
  expect_io_error(write("slash.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/ /2 3\n"),
                  {"line 4", "'' is not a valid vertex index"});
}

TEST_F(MeshIo, ObjForwardReferencesAreAllowed) {
  const Mesh m = focal::read_mesh(write("fwd.obj", "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"));
  expect_faces(m, {{0, 1, 2}}, {0});
  EXPECT_EQ(m.V.rows(), 3);
}

// ---------------------------------------------------------------------------------------------
// OFF reading

TEST_F(MeshIo, OffVariantsCommentsAndPolygons) {
  const Mesh m = focal::read_mesh(write("c.off",
                                        "# leading comment\n"
                                        "COFF\n"
                                        "\n"
                                        "4 2 0 # counts\n"
                                        "0 0 0 255 0 0 255\n"
                                        "1 0 0 0 255 0 255\n"
                                        "1 1 0 0 0 255 255   # colour per vertex\n"
                                        "0 1 0 9 9 9 9\n"
                                        "4 0 1 2 3 1 0 0\n"  // quad with a face colour
                                        "3 3 2 1\n"));
  expect_same(m.V, rows({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}));
  EXPECT_FALSE(m.has_normals());
  expect_faces(m, {{0, 1, 2}, {0, 2, 3}, {3, 2, 1}}, {0, 0, 1});

  const Mesh n = focal::read_mesh(write("n.off",
                                        "NOFF 3 1 0\n"  // counts on the keyword line
                                        "0 0 0 0 0 1\n1 0 0 0 0.6 0.8\n0 1 0 1 0 0\n3 0 1 2\n"));
  ASSERT_TRUE(n.has_normals());
  expect_same(n.N, rows({{0, 0, 1}, {0, 0.6, 0.8}, {1, 0, 0}}));

  const Mesh st = focal::read_mesh(write("st.off",
                                         "STCNOFF\n3 1\n"
                                         "0 0 0 0 0 1 1 1 1 1 0.5 0.5\n"
                                         "1 0 0 0 0 1 1 1 1 1 0.5 0.5\n"
                                         "0 1 0 0 0 1 1 1 1 1 0.5 0.5\n3 0 1 2\n"));
  EXPECT_TRUE(st.has_normals());
  EXPECT_EQ(st.V(1, 0), 1.0);
}

TEST_F(MeshIo, OffErrorsNameLineAndFace) {
  std::string forty = "OFF\n40 6 0\n";
  for (int i = 0; i < 40; ++i) forty += std::to_string(i) + " 0 0\n";
  forty += "3 0 1 2\n3 0 1 2\n3 0 1 2\n3 0 1 2\n3 0 1 2\n3 0 99 2\n";
  expect_io_error(write("range.off", forty),
                  {"line 48", "face 5 refers to vertex 99 but there are 40 vertices"});
  expect_io_error(write("v2.off", "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n"),
                  {"line 4", "vertex 1: expected 3 coordinates, got 2"});
  expect_io_error(write("n5.off", "NOFF\n1 0 0\n0 0 0 0 0\n"),
                  {"line 3", "expected 6 coordinates and normal components, got 5"});
  expect_io_error(write("f2.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
                  {"line 6", "face 0 has 2 vertices"});
  expect_io_error(write("fshort.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n"),
                  {"line 6", "face 0: expected 4 vertex indices, got 3"});
  expect_io_error(write("ends.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                  {"file ends inside face 1 of 2"});
  expect_io_error(write("huge.off", "OFF\n1000000000000 1 0\n0 0 0\n"), {"1000000000000 vertices"});
  expect_io_error(write("keyword.off", "PLY\n3 1 0\n"), {"line 1", "not an OFF file"});
  expect_io_error(write("4off.off", "4OFF\n3 1 0\n"), {"line 1", "4OFF"});
  expect_io_error(write("binary.off", "OFF BINARY\n"), {"binary OFF"});
  expect_io_error(write("counts.off", "OFF\n3 x 0\n"), {"line 2", "counts"});
  expect_io_error(write("empty.off", "# nothing\n"), {"empty file"});
}

// ---------------------------------------------------------------------------------------------
// STL reading

const char* kAsciiStl =
    "solid two\n"
    "  facet normal 0 0 1\n"
    "    outer loop\n"
    "      vertex 0 0 0\n"
    "      vertex 1 0 0\n"
    "      vertex 0 1 0\n"
    "    endloop\n"
    "  endfacet\n"
    "  FACET NORMAL 0 0 0\n"
    "    OUTER LOOP\n"
    "      VERTEX 1 0 0\n"
    "      VERTEX 1 1 0.5e-1\n"
    "      VERTEX 0 1 0\n"
    "    ENDLOOP\n"
    "  ENDFACET\n"
    "endsolid two\n";

Bytes binary_stl(const std::string& header80, const std::vector<std::array<float, 9>>& facets) {
  Bytes b;
  std::string header = header80;
  header.resize(80, ' ');
  b.text(header).put(static_cast<std::uint32_t>(facets.size()));
  for (const auto& f : facets) {
    b.put(0.0f).put(0.0f).put(1.0f);
    for (const float x : f) b.put(x);
    b.put(std::uint16_t{0});
  }
  return b;
}

TEST_F(MeshIo, StlCornersAreWeldedInFirstAppearanceOrder) {
  const Mesh m = focal::read_mesh(write("a.stl", kAsciiStl));
  // The shared corners (1,0,0) and (0,1,0) become one vertex each, numbered where first seen.
  expect_same(m.V, rows({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0.05}}));
  expect_faces(m, {{0, 1, 2}, {1, 3, 2}}, {0, 1});
  EXPECT_EQ(m.corner_vertex, (Eigen::VectorXi(6) << 0, 1, 2, 1, 3, 2).finished());
  EXPECT_FALSE(m.has_normals());
  // --no-weld: every corner its own vertex, in file order.
  const Mesh apart = focal::read_mesh(file("a.stl"), {.weld = false});
  expect_same(apart.V, rows({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0.05}, {0, 1, 0}}));
  expect_faces(apart, {{0, 1, 2}, {3, 4, 5}}, {0, 1});
  EXPECT_EQ(apart.corner_vertex, (Eigen::VectorXi(6) << 0, 1, 2, 3, 4, 5).finished());
  // Indexed formats keep their vertices: no corner map.
  EXPECT_EQ(
      focal::read_mesh(write("t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")).corner_vertex.size(),
      0);
}

TEST_F(MeshIo, StlBinaryIsDetectedBySizeEvenWithASolidHeader) {
  const std::vector<std::array<float, 9>> facets = {{0, 0, 0, 1, 0, 0, 0, 1, 0},
                                                    {1, 0, 0, 1, 1, 0.25f, 0, 1, 0}};
  for (const std::string header : {"binary stl", "solid exported by a CAD tool"}) {
    const Mesh m = focal::read_mesh(write("b.stl", binary_stl(header, facets).data));
    expect_same(m.V, rows({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0.25}}));
    expect_faces(m, {{0, 1, 2}, {1, 3, 2}}, {0, 1});
  }
  const Mesh empty = focal::read_mesh(write("e.stl", binary_stl("", {}).data));
  EXPECT_EQ(empty.V.rows(), 0);
}

TEST_F(MeshIo, StlWeldingExactAndWithTolerance) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // -0.0 is 0.0; NaN corners never weld (NaN equals nothing); 1e-7 apart welds only with a
  // tolerance, and then to the first vertex within reach.
  const std::vector<std::array<float, 9>> facets = {{0, 0, 0, 1, 0, 0, 0, 1, 0},
                                                    {-0.0f, 0, -0.0f, 1e-7f, 1, 0, nan, 0, 0},
                                                    {1, 1e-7f, 0, 0, 1, 1e-7f, nan, 0, 0}};
  const fs::path p = write("w.stl", binary_stl("w", facets).data);
  const Mesh exact = focal::read_mesh(p);
  EXPECT_EQ(exact.corner_vertex, (Eigen::VectorXi(9) << 0, 1, 2, 0, 3, 4, 5, 6, 7).finished());
  EXPECT_EQ(exact.V.rows(), 8);
  const Mesh loose = focal::read_mesh(p, {.weld_tolerance = 1e-6});
  EXPECT_EQ(loose.corner_vertex, (Eigen::VectorXi(9) << 0, 1, 2, 0, 2, 3, 1, 2, 4).finished());
  expect_same(loose.V.topRows(3), rows({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
  // 1e-7 away from (1,0,0) and from (0,1,0) alike at tolerance 2: the first vertex wins.
  const Mesh coarse = focal::read_mesh(p, {.weld_tolerance = 2.0});
  EXPECT_EQ(coarse.corner_vertex(4), 0);
  expect_error<focal::InvalidInput>([&] { (void)focal::read_mesh(p, {.weld_tolerance = -1}); },
                                    {"weld_tolerance"});
}

TEST_F(MeshIo, StlWeldingClosesASphere) {
  // A closed sphere as STL: every vertex is shared by its triangles after welding, and the
  // welded vertex count is the indexed mesh's.
  const int n = 60;
  std::vector<std::array<float, 9>> facets;
  const auto point = [&](int i, int j) {
    const double t = M_PI * i / n, p = 2 * M_PI * (j % (2 * n)) / (2 * n);
    const bool pole = i == 0 || i == n;
    return std::array<float, 3>{pole ? 0.0f : static_cast<float>(std::sin(t) * std::cos(p)),
                                pole ? 0.0f : static_cast<float>(std::sin(t) * std::sin(p)),
                                static_cast<float>(std::cos(t))};
  };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < 2 * n; ++j) {
      const auto a = point(i, j), b = point(i + 1, j), c = point(i + 1, j + 1), d = point(i, j + 1);
      if (i + 1 < n) facets.push_back({a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]});
      if (i > 0) facets.push_back({a[0], a[1], a[2], c[0], c[1], c[2], d[0], d[1], d[2]});
    }
  }
  const Mesh m = focal::read_mesh(write("sphere.stl", binary_stl("s", facets).data));
  EXPECT_EQ(m.V.rows(), 2 + (n - 1) * 2 * n);
  EXPECT_EQ(m.corner_vertex.size(), 3 * static_cast<Eigen::Index>(facets.size()));
}

TEST_F(MeshIo, StlAsciiVariantsAreNotTakenForBinary) {
  // Upper-case keywords, a UTF-8 byte order mark, a comment line before `solid`: ascii, welded.
  std::string upper = kAsciiStl;
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  for (const std::string& text :
       {upper, "\xEF\xBB\xBF" + std::string(kAsciiStl), "# exported\n" + std::string(kAsciiStl)}) {
    const Mesh m = focal::read_mesh(write("v.stl", text));
    expect_same(m.V, rows({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0.05}}));
  }
}

TEST_F(MeshIo, StlErrors) {
  std::string truncated = binary_stl("solid x", {{0, 0, 0, 1, 0, 0, 0, 1, 0}}).data;
  truncated[80] = 3;  // claims 3 facets, holds 1
  expect_io_error(write("t.stl", truncated), {"byte offset 134", "file ends inside facet 1 of 3"});
  std::string extra = binary_stl("model", {{0, 0, 0, 1, 0, 0, 0, 1, 0}}).data + "xx";
  expect_io_error(write("x.stl", extra), {"byte offset 134", "2 bytes follow the 1 facets"});
  expect_io_error(write("short.stl", "abc"), {"too short"});
  expect_io_error(write("kw.stl", "solid a\n facet normal 0 0 1\n  outer loop\n   vertx 0 0 0\n"),
                  {"line 4", "unknown keyword 'vertx'"});
  expect_io_error(write("order.stl", "solid a\n outer loop\n"), {"line 2", "unexpected 'outer'"});
  expect_io_error(write("v2.stl", "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n"),
                  {"line 4", "expected 3 coordinates, got 2"});
  expect_io_error(write("two.stl",
                        "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                        "vertex 1 0 0\nendloop\nendfacet\nendsolid a\n"),
                  {"line 7", "facet 0 has 2 vertices"});
  expect_io_error(write("open.stl", "solid a\nfacet normal 0 0 1\n"), {"inside a solid"});
}

// ---------------------------------------------------------------------------------------------
// Writers: atomicity and failures

TEST_F(MeshIo, FocalMeshPairIsWrittenAllOrNothing) {
  focal::FocalMeshes meshes;
  for (focal::FocalMesh* g : {&meshes.gamma1, &meshes.gamma2}) {
    g->mesh = sample_mesh(false);
    g->flag = focal::VectorXu8::Zero(g->mesh.V.rows());
  }
  // The second target is a folder: the first keeps its old contents, no temporary is left.
  write("fm.focal1.ply", "old\n");
  fs::create_directory(file("fm.focal2.ply"));
  expect_error<focal::IoError>(
      [&] { focal::write_focal_meshes_ply(file("fm.focal1.ply"), file("fm.focal2.ply"), meshes); },
      {"fm.focal2.ply", "directory"});
  EXPECT_EQ(slurp(file("fm.focal1.ply")), "old\n");
  EXPECT_EQ(folder_entries(), (std::vector<std::string>{"fm.focal1.ply", "fm.focal2.ply"}));
  // Neither exists and the second cannot be validated: neither is created.
  meshes.gamma2.flag.resize(1);
  expect_error<focal::InvalidInput>(
      [&] { focal::write_focal_meshes_ply(file("a.focal1.ply"), file("a.focal2.ply"), meshes); },
      {"focal_flag"});
  EXPECT_FALSE(fs::exists(file("a.focal1.ply")));
  // Both writable: both replaced, no backup left behind.
  meshes.gamma2.flag = focal::VectorXu8::Zero(meshes.gamma2.mesh.V.rows());
  fs::remove(file("fm.focal2.ply"));
  write("fm.focal2.ply", "old\n");
  focal::write_focal_meshes_ply(file("fm.focal1.ply"), file("fm.focal2.ply"), meshes);
  EXPECT_EQ(focal::read_mesh(file("fm.focal1.ply")).V.rows(), meshes.gamma1.mesh.V.rows());
  EXPECT_EQ(focal::read_mesh(file("fm.focal2.ply")).V.rows(), meshes.gamma2.mesh.V.rows());
  EXPECT_EQ(folder_entries(), (std::vector<std::string>{"fm.focal1.ply", "fm.focal2.ply"}));
}

TEST_F(MeshIo, WritersWriteThroughALinkAndRefuseADanglingOne) {
  write("target.obj", "old\n");
  fs::create_symlink("target.obj", file("link.obj"));
  focal::write_obj(file("link.obj"), sample_mesh(false));
  EXPECT_TRUE(fs::is_symlink(file("link.obj")));
  EXPECT_EQ(focal::read_mesh(file("target.obj")).V.rows(), sample_mesh(false).V.rows());
  fs::create_symlink("nowhere.obj", file("dangling.obj"));
  expect_error<focal::IoError>([&] { focal::write_obj(file("dangling.obj"), sample_mesh(false)); },
                               {"dangling.obj", "link to a missing"});
  EXPECT_FALSE(fs::exists(file("nowhere.obj")));
}

TEST_F(MeshIo, WriteIntoMissingFolderFailsAndCreatesNothing) {
  const Mesh m = sample_mesh(true);
  const fs::path p = file("no/such/folder/out.ply");
  expect_error<focal::IoError>([&] { focal::write_ply(p, m); }, {p.string()});
  expect_error<focal::IoError>([&] { focal::write_obj(p.parent_path() / "o.obj", m); },
                               {"out.ply" == std::string() ? "" : "o.obj"});
  expect_error<focal::IoError>([&] { focal::write_off(p.parent_path() / "o.off", m); }, {"o.off"});
  const std::vector<focal::CsvColumn> cols{{"a", Eigen::VectorXd::Zero(2)}};
  expect_error<focal::IoError>([&] { focal::write_csv(p.parent_path() / "o.csv", cols); },
                               {"o.csv"});
  EXPECT_FALSE(fs::exists(file("no")));
  EXPECT_TRUE(folder_entries().empty());
}

TEST_F(MeshIo, FailedWriteLeavesTheExistingFileUntouched) {
  const Mesh m = sample_mesh(false);
  const fs::path p = write("keep.ply", "precious contents");
  std::vector<focal::VertexProperty> props{
      {"k1", Eigen::VectorXd::Zero(3), focal::PropertyType::float32}};  // 3 values, 5 vertices
  expect_error<focal::InvalidInput>([&] { focal::write_ply(p, m, props); }, {"k1"});
  EXPECT_EQ(slurp(p), "precious contents");

  const fs::path csv = write("keep.csv", "precious too");
  const std::vector<focal::CsvColumn> uneven{{"a", Eigen::VectorXd::Zero(2)},
                                             {"b", Eigen::VectorXd::Zero(3)}};
  expect_error<focal::InvalidInput>([&] { focal::write_csv(csv, uneven); },
                                    {"keep.csv", "'b' has 3 values"});
  EXPECT_EQ(slurp(csv), "precious too");
  EXPECT_EQ(folder_entries(), (std::vector<std::string>{"keep.csv", "keep.ply"}));
}

TEST_F(MeshIo, FailedRenameRemovesTheTemporaryFile) {
  // The destination is a non-empty folder: the body is written, then the rename fails.
  fs::create_directories(file("taken.obj") / "inside");
  expect_error<focal::IoError>([&] { focal::write_obj(file("taken.obj"), sample_mesh(true)); },
                               {file("taken.obj").string()});
  EXPECT_EQ(folder_entries(), (std::vector<std::string>{"taken.obj"}));
  EXPECT_TRUE(fs::is_directory(file("taken.obj") / "inside"));
}

TEST_F(MeshIo, WriteReplacesAnExistingFile) {
  const fs::path p = write("m.off", "old contents that are longer than the new ones ........");
  Mesh m;
  m.V = rows({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  focal::write_off(p, m);
  EXPECT_EQ(slurp(p), "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(folder_entries(), (std::vector<std::string>{"m.off"}));
}

TEST_F(MeshIo, WritersRejectInvalidMeshes) {
  Mesh m = sample_mesh(true);
  m.N.conservativeResize(3, 3);
  expect_error<focal::InvalidInput>([&] { focal::write_obj(file("bad.obj"), m); },
                                    {"bad.obj", "3 normals for 5 vertices"});
  m = sample_mesh(false);
  m.F(2, 1) = -1;
  expect_error<focal::InvalidInput>([&] { focal::write_off(file("bad.off"), m); },
                                    {"bad.off", "face 2"});
  EXPECT_TRUE(folder_entries().empty());
}

// ---------------------------------------------------------------------------------------------
// CSV

TEST_F(MeshIo, CsvFormatsNumbersShortestWithNanAndInf) {
  Eigen::VectorXd k1(6);
  k1 << 0.1, kNaN, kInf, -kInf, 1.0 / 3.0, -0.0;
  Eigen::VectorXd big(6);
  big << 1e300, 5e-324, 100, -2.5, 123456789012345678.0, 0;
  const std::vector<focal::CsvColumn> cols{
      {"k1", k1},
      {"big", big},
      {"class",
       std::vector<std::string>{"elliptic", "undefined", "flat", "a,b", "say \"hi\"", "umbilic"}}};
  focal::write_csv(file("t.csv"), cols);
  EXPECT_EQ(slurp(file("t.csv")),
            "k1,big,class\n"
            "0.1,1e+300,elliptic\n"
            "nan,5e-324,undefined\n"
            "inf,100,flat\n"
            "-inf,-2.5,\"a,b\"\n"
            "0.3333333333333333,123456789012345680,\"say \"\"hi\"\"\"\n"
            "-0,0,umbilic\n");
  // -NaN is written as plain nan too.
  Eigen::VectorXd neg(1);
  neg << -kNaN;
  focal::write_csv(file("n.csv"), std::vector<focal::CsvColumn>{{"x", neg}});
  EXPECT_EQ(slurp(file("n.csv")), "x\nnan\n");
  focal::write_csv(file("e.csv"), {});
  EXPECT_EQ(slurp(file("e.csv")), "\n");
}

// The rows are formatted in parallel blocks (2048 rows, 16 to a batch): the same bytes for any
// thread count, across block and batch edges, as the rows written one by one.
TEST_F(MeshIo, CsvIsTheSameForAnyThreadCount) {
  const Eigen::Index n = 2048 * 16 * 2 + 777;
  Eigen::VectorXd x(n);
  std::vector<std::string> words(static_cast<std::size_t>(n));
  std::string expected = "x,w\n";
  for (Eigen::Index i = 0; i < n; ++i) {
    x[i] = i % 7 == 0 ? kNaN : static_cast<double>(i);
    words[static_cast<std::size_t>(i)] = i % 5 == 0 ? "a,b" : "w";
    expected += (i % 7 == 0 ? std::string("nan") : std::to_string(i)) +
                (i % 5 == 0 ? ",\"a,b\"\n" : ",w\n");
  }
  const std::vector<focal::CsvColumn> cols{{"x", x}, {"w", words}};
  for (const int threads : {1, 2, 3}) {
    const ExecutionScope scope({.threads = threads});
    focal::write_csv(file("p.csv"), cols);
    EXPECT_EQ(slurp(file("p.csv")), expected) << threads << " threads";
  }
}

// ---------------------------------------------------------------------------------------------
// Robustness: mutated and truncated files must give a valid mesh or an IoError, never a crash,
// a different exception or indices out of range. (A cheap, deterministic stand-in for fuzzing.)

TEST_F(MeshIo, MutatedFilesGiveAValidMeshOrAnIoError) {
  const Mesh m = sample_mesh(true);
  std::vector<std::pair<std::string, std::string>> seeds;
  focal::write_ply(file("s.ply"), m);
  seeds.emplace_back("ply", slurp(file("s.ply")));
  focal::write_ply(file("s.ply"), m, {}, ascii_options());
  seeds.emplace_back("ply", slurp(file("s.ply")));
  seeds.emplace_back("ply", rich_ply("binary_big_endian"));
  focal::write_obj(file("s.obj"), m);
  seeds.emplace_back("obj", slurp(file("s.obj")));
  focal::write_off(file("s.off"), m);
  seeds.emplace_back("off", slurp(file("s.off")));
  seeds.emplace_back("stl", kAsciiStl);
  seeds.emplace_back("stl", binary_stl("solid", {{0, 0, 0, 1, 0, 0, 0, 1, 0}}).data);

  std::mt19937 rng(12345);
  const char alphabet[] = "0123456789 -+.\n/eE#xnaif\xff\x7f";
  int accepted = 0;
  int rejected = 0;
  for (int iteration = 0; iteration < 3000; ++iteration) {
    const auto& [ext, seed] = seeds[static_cast<std::size_t>(iteration) % seeds.size()];
    std::string data = seed;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits && !data.empty(); ++e) {
      const std::size_t at = rng() % data.size();
      switch (rng() % 4) {
        case 0:
          data[at] = alphabet[rng() % (sizeof alphabet - 1)];
          break;
        case 1:
          data[at] = static_cast<char>(rng());
          break;
        case 2:
          data.erase(at, 1 + rng() % 8);
          break;
        default:
          data.resize(at);
      }
    }
    const fs::path p = write("fuzz." + ext, data);
    try {
      const Mesh r = focal::read_mesh(p);
      ASSERT_EQ(r.F.rows(), r.face_source.size());
      if (r.F.size() > 0) {
        ASSERT_GE(r.F.minCoeff(), 0) << data;
        ASSERT_LT(r.F.maxCoeff(), r.V.rows()) << data;
      }
      ASSERT_TRUE(r.N.rows() == 0 || r.N.rows() == r.V.rows());
      ++accepted;
    } catch (const focal::IoError&) {
      ++rejected;
    }
  }
  EXPECT_GT(rejected, 0);
  EXPECT_GT(accepted, 0);
}

// ---------------------------------------------------------------------------------------------
// Dirty files (issue 6): empty, truncated anywhere, wrong byte order, bytes that are not UTF-8.
// The readers are also fuzzed (fuzz/, scripts/fuzz.sh); these are the deterministic cases.

TEST_F(MeshIo, EmptyFilesAreErrorsInEveryFormat) {
  expect_io_error(write("empty.ply", ""), {"not a PLY file"});
  expect_io_error(write("empty.off", ""), {"empty file"});
  expect_io_error(write("empty.stl", ""), {"too short", "0 bytes"});
  expect_io_error(write("empty.obj", ""), {"empty file (0 bytes)"});
  // OBJ has no header: a file without vertices is not taken for an empty mesh (issue 13).
  expect_io_error(write("comment.obj", "# nothing yet\n"), {"comment.obj", "no vertices"});
}

TEST_F(MeshIo, BytesThatCannotBeObjAreErrors) {
  expect_io_error(write("html.obj", "<!DOCTYPE html>\n<html><body>hi</body></html>\n"),
                  {"html.obj", "no vertices"});
  expect_io_error(write("text.obj", "just some words\nand more\n"), {"no vertices"});
  expect_io_error(write("nul.obj", std::string("v 0 0 0\n\0\0\0", 11)),
                  {"byte offset 8", "control byte 0x00", "not OBJ text"});
  expect_io_error(write("elf.obj", std::string("\x7F"
                                               "ELF\x02\x01\x01",
                                               7)),
                  {"byte offset 0", "0x7F"});
  expect_io_error(write("png.obj", std::string("\x89PNG\r\n\x1A\n", 8)), {"byte offset 6", "0x1A"});
  expect_io_error(write("utf16.obj", std::string("\xFF\xFEv\0 \0", 6)), {"UTF-16"});
  // A PLY or OFF renamed .obj: no `v` lines.
  expect_io_error(write("ply.obj", "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n"),
                  {"no vertices"});
  expect_io_error(write("off.obj", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), {"no vertices"});
  // Random bytes: an error, never an empty mesh.
  std::mt19937 random(13);
  for (int trial = 0; trial < 20; ++trial) {
    std::string bytes(256, '\0');
    for (char& c : bytes) c = static_cast<char>(random() & 0xFF);
    expect_io_error(write("random.obj", bytes), {"random.obj"});
  }
}

TEST_F(MeshIo, InputsThatAreNotRegularFilesAreErrors) {
  const fs::path fifo = file("f.obj");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  expect_io_error(fifo, {"f.obj", "FIFO", "not a regular file"});  // returns at once
  if (fs::exists("/dev/zero")) {
    fs::create_symlink("/dev/zero", file("zero.ply"));
    expect_io_error(file("zero.ply"), {"zero.ply", "character device"});
  }
}

/// Every proper prefix of `data` but the one without just the final byte, read as `name`: either
/// an IoError naming the file, or, when `prefix_ok`, a mesh whose vertices are the first ones of
/// `full` and whose faces index only them. Returns how many prefixes were read as meshes.
class MeshIoCut : public MeshIo {
 protected:
  int read_every_prefix(const std::string& name, const std::string& data, const Mesh& full,
                        bool prefix_ok, std::size_t header_bytes) {
    int meshes = 0;
    for (std::size_t n = 0; n + 1 < data.size(); ++n) {
      const fs::path p = write(name, data.substr(0, n));
      try {
        const Mesh m = focal::read_mesh(p);
        EXPECT_TRUE(prefix_ok) << name << " cut at " << n << " was read";
        if (!prefix_ok) continue;
        EXPECT_LE(m.V.rows(), full.V.rows()) << n;
        // Only the last vertex read may have lost digits at the cut ("1e-300" -> "1e-3").
        const Eigen::Index whole = std::max<Eigen::Index>(m.V.rows() - 1, 0);
        expect_same(m.V.topRows(whole), full.V.topRows(whole));
        if (m.F.size() > 0) {
          EXPECT_LT(m.F.maxCoeff(), m.V.rows()) << n;
        }
        ++meshes;
      } catch (const focal::IoError& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.rfind(p.string() + ": ", 0), 0u) << message;
        // Past the header the message says where: a line (text) or a byte offset (binary).
        if (n > header_bytes) {
          EXPECT_TRUE(message.find(": line ") != std::string::npos ||
                      message.find(": byte offset ") != std::string::npos)
              << name << " cut at " << n << ": " << message;
        }
      }
    }
    return meshes;
  }
};

TEST_F(MeshIoCut, FilesCutAtEveryByteAreErrorsThatSayWhere) {
  const Mesh m = sample_mesh(true);
  // Formats that declare their counts: any cut but the final line break is an error.
  focal::write_ply(file("full.ply"), m);
  const std::string binary = slurp(file("full.ply"));
  read_every_prefix("cut.ply", binary, m, false, binary.find("end_header") + 11);
  focal::write_ply(file("full.ply"), m, {}, ascii_options());
  const std::string ascii = slurp(file("full.ply"));
  read_every_prefix("cut.ply", ascii, m, false, ascii.find("end_header") + 11);
  focal::write_off(file("full.off"), m);
  const std::string off = slurp(file("full.off"));
  read_every_prefix("cut.off", off, m, false, off.find('\n', 5) + 1);
  Mesh soup;  // STL: three corners per facet
  soup.V = rows({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  read_every_prefix("cut.stl", binary_stl("b", {{0, 0, 0, 1, 0, 0, 0, 1, 0}}).data, soup, false,
                    84);
  // OBJ has no counts: a cut at a line end is a shorter valid file, one inside a line an error.
  focal::write_obj(file("full.obj"), m);
  const std::string obj = slurp(file("full.obj"));
  EXPECT_GT(read_every_prefix("cut.obj", obj, m, true, 0), 0);
  // Ascii STL: only cuts in the final `endsolid` line (a solid without its end) can be read.
  Mesh two;  // welded
  two.V = rows({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0.05}});
  const std::string stl = kAsciiStl;
  const int read = read_every_prefix("cut.stl", stl, two, true, std::strlen("solid"));
  EXPECT_LE(read, static_cast<int>(std::string("endsolid two").size()));
}

TEST_F(MeshIo, BinaryPlyInTheWrongByteOrder) {
  // Declared big endian, written little endian: the face indices come out byte-swapped (index 1
  // reads as 16777216) and are rejected with the face and its byte offset.
  std::string swapped = slurp([&] {
    focal::write_ply(file("le.ply"), sample_mesh(false));
    return file("le.ply");
  }());
  swapped.replace(swapped.find("binary_little_endian"), 20, "binary_big_endian");
  expect_io_error(write("swapped.ply", swapped),
                  {"byte offset", "face 0 refers to vertex 16777216 but there are 5 vertices"});
  // Without faces nothing in the file can tell: the positions are read byte-swapped, as declared.
  Bytes le;
  le.text(
      "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty double x\n"
      "property double y\nproperty double z\nend_header\n");
  le.put(1.0).put(2.0).put(0.0);
  const Mesh m = focal::read_mesh(write("cloud.ply", le.data));
  const auto swap = [](double v) {
    std::array<char, 8> b;
    std::memcpy(b.data(), &v, 8);
    std::reverse(b.begin(), b.end());
    std::memcpy(&v, b.data(), 8);
    return v;
  };
  expect_same(m.V, rows({{swap(1.0), swap(2.0), 0.0}}));
}

TEST_F(MeshIo, BytesThatAreNotUtf8) {
  // In comments, names and ignored statements they are skipped like any other byte...
  const Mesh obj = focal::read_mesh(
      write("latin1.obj", "# caf\xe9\ng gr\xfc\xdf\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  EXPECT_EQ(obj.F.rows(), 1);
  const Mesh ply = focal::read_mesh(
      write("latin1.ply",
            "ply\nformat ascii 1.0\ncomment \xff\xfe\nelement vertex 1\nproperty float x\n"
            "property float y\nproperty float z\nproperty float \xe9t\xe9\n"
            "end_header\n1 2 3 4\n"));
  expect_same(ply.V, rows({{1, 2, 3}}));
  const Mesh stl =
      focal::read_mesh(write("latin1.stl", std::string(kAsciiStl).replace(6, 3, "\xe9\xe9\xe9")));
  EXPECT_EQ(stl.V.rows(), 4);
  // ...and where a number or keyword belongs they are an error that names the line.
  expect_io_error(write("v.obj", "v 0 0 0\nv 1 \xff 0\n"), {"line 2", "is not a number"});
  expect_io_error(write("v.off", "OFF\n1 0 0\n0 \xc3\xa9 0\n"), {"line 3"});
  expect_io_error(write("v.ply",
                        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                        "property float y\nproperty float z\nend_header\n1 \x80 3\n"),
                  {"line 8", "is not a number"});
  expect_io_error(write("k.ply",
                        "ply\nformat ascii 1.0\n\xef\xbb\xbf"
                        "element vertex 0\nend_header\n"),
                  {"line 3", "unknown header keyword"});
  // A UTF-8 byte order mark before an OBJ file is skipped: the first vertex must not be lost.
  const Mesh bom =
      focal::read_mesh(write("bom.obj", "\xef\xbb\xbfv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  EXPECT_EQ(bom.V.rows(), 3);
  expect_faces(bom, {{0, 1, 2}}, {0});
}

// ---------------------------------------------------------------------------------------------
// Parallel binary reading and writing: the same bytes and meshes for any thread count

/// The read_mesh() message for p, or "" when it reads.
std::string read_error(const fs::path& p, int threads = 0) {
  const ExecutionScope scope({.threads = threads});
  try {
    (void)focal::read_mesh(p);
  } catch (const focal::IoError& e) {
    return e.what();
  }
  return "";
}

/// A binary PLY big enough for many parallel blocks, with every scalar type among the vertex
/// properties (the roles in different types) and extra scalars around the face list.
struct BigPly {
  std::string data;
  Mesh expected;
  std::vector<std::size_t> face_offsets;  ///< byte offset of each face record
};

BigPly big_binary_ply(bool big_endian, Eigen::Index nv, Eigen::Index nf, bool wide_lists) {
  BigPly out;
  const std::string list = wide_lists ? "ushort uint" : "uchar int";
  Bytes b(big_endian);
  b.text(std::string("ply\nformat ") + (big_endian ? "binary_big_endian" : "binary_little_endian") +
         " 1.0\nelement vertex " + std::to_string(nv) +
         "\nproperty char a\nproperty float x\nproperty double y\nproperty short s\n"
         "property int z\nproperty uchar c\nproperty double nx\nproperty float ny\n"
         "property ushort nz\nproperty uint u\nelement face " +
         std::to_string(nf) + "\nproperty uchar flag\nproperty list " + list +
         " vertex_indices\nproperty float q\nelement tail 1\nproperty int t\nend_header\n");
  Mesh& m = out.expected;
  m.V.resize(nv, 3);
  m.N.resize(nv, 3);
  std::mt19937 rng(7);
  for (Eigen::Index i = 0; i < nv; ++i) {
    const float x = static_cast<float>(rng()) / 4096.0f - 5e5f;
    const double y = static_cast<double>(rng()) * 1e-7 - 200.0;
    const auto z = static_cast<std::int32_t>(rng());
    const double nx = static_cast<double>(rng()) / 3.0;
    const float ny = -static_cast<float>(rng() % 1000) / 7.0f;
    const auto nz = static_cast<std::uint16_t>(rng());
    b.put(static_cast<std::int8_t>(rng())).put(x).put(y).put(static_cast<std::int16_t>(rng()));
    b.put(z)
        .put(static_cast<std::uint8_t>(rng()))
        .put(nx)
        .put(ny)
        .put(nz)
        .put(static_cast<std::uint32_t>(rng()));
    m.V.row(i) << x, y, z;
    m.N.row(i) << nx, ny, nz;
  }
  m.F.resize(nf, 3);
  m.face_source = Eigen::VectorXi::LinSpaced(nf, 0, static_cast<int>(nf - 1));
  for (Eigen::Index f = 0; f < nf; ++f) {
    out.face_offsets.push_back(b.data.size());
    b.put(std::uint8_t{1});
    if (wide_lists) {
      b.put(std::uint16_t{3});
    } else {
      b.put(std::uint8_t{3});
    }
    for (int c = 0; c < 3; ++c) {
      m.F(f, c) = static_cast<std::int32_t>(rng() % static_cast<std::uint32_t>(nv));
      if (wide_lists) {
        b.put(static_cast<std::uint32_t>(m.F(f, c)));
      } else {
        b.put(m.F(f, c));
      }
    }
    b.put(0.5f);
  }
  b.put(std::int32_t{42});
  out.data = b.data;
  return out;
}

TEST_F(MeshIo, PlyBinaryReadIsTheSameForAnyThreadCount) {
  // Empty elements take the fixed-size paths too (a fuzzer find: no offsets on null arrays).
  const Mesh empty = focal::read_mesh(write("empty.ply", binary_header(0, 0)));
  EXPECT_EQ(empty.V.rows(), 0);
  EXPECT_EQ(empty.F.rows(), 0);
  for (const bool big_endian : {false, true}) {
    const BigPly ply = big_binary_ply(big_endian, 50000, 90000, big_endian);
    const fs::path p = write("big.ply", ply.data);
    for (const int threads : {1, 2, 3}) {
      const ExecutionScope scope({.threads = threads});
      SCOPED_TRACE("big endian " + std::to_string(big_endian) + ", threads " +
                   std::to_string(threads));
      expect_same_mesh(ply.expected, focal::read_mesh(p));
    }
  }
}

TEST_F(MeshIo, PlyBinaryParallelReadFallsBackWithTheSameResultsAndErrors) {
  const BigPly ply = big_binary_ply(false, 50000, 90000, false);
  const std::size_t list_at = 1;  // the count byte follows the uchar flag
  // Face 70000 refers to vertex 50000: the error names that face and its offset.
  std::string range = ply.data;
  const std::size_t bad = ply.face_offsets[70000];
  const std::int32_t too_big = 50000;
  std::memcpy(&range[bad + list_at + 1 + 4], &too_big, 4);  // little endian hosts only
  // Face 30000 has 2 vertices: the second index becomes the float q.
  std::string two = ply.data;
  two[ply.face_offsets[30000] + list_at] = 2;
  // File cut inside face 89999.
  const std::string cut = ply.data.substr(0, ply.face_offsets[89999] + 5);
  if (std::endian::native != std::endian::little) GTEST_SKIP() << "patches little endian bytes";
  const fs::path pr = write("range.ply", range);
  const fs::path pt = write("two.ply", two);
  const fs::path pc = write("cut.ply", cut);
  std::vector<std::string> first;
  for (const int threads : {1, 2}) {
    const std::vector<std::string> messages = {read_error(pr, threads), read_error(pt, threads),
                                               read_error(pc, threads)};
    EXPECT_NE(messages[0].find("byte offset " + std::to_string(bad) +
                               ": face 70000 refers to vertex 50000 but there are 50000 vertices"),
              std::string::npos)
        << messages[0];
    EXPECT_NE(messages[1].find("byte offset " + std::to_string(ply.face_offsets[30000]) +
                               ": face 30000 has 2 vertices"),
              std::string::npos)
        << messages[1];
    EXPECT_NE(messages[2].find("byte offset " + std::to_string(ply.face_offsets[89999]) +
                               ": file ends inside face 89999 of 90000"),
              std::string::npos)
        << messages[2];
    if (first.empty()) {
      first = messages;
    } else {
      EXPECT_EQ(first, messages);
    }
  }

  // A quad among the triangles: read serially, fanned, with its face index.
  Bytes q;
  q.text(binary_header(4, 2));
  for (int i = 0; i < 12; ++i) q.put(static_cast<float>(i));
  q.put(std::uint8_t{4}).put(0).put(1).put(2).put(3);
  q.put(std::uint8_t{3}).put(3).put(2).put(1);
  for (const int threads : {1, 2}) {
    const ExecutionScope scope({.threads = threads});
    expect_faces(focal::read_mesh(write("quad.ply", q.data)), {{0, 1, 2}, {0, 2, 3}, {3, 2, 1}},
                 {0, 0, 1});
  }
}

/// The bytes the serial writer produced: each vertex x y z (nx ny nz) double then each property
/// in its type, little endian; faces as uchar 3 and three ints. With Precision::float32 the
/// positions, normals and float64 properties as static_cast<float> of their values.
std::string reference_ply_body(const Mesh& m, const std::vector<focal::VertexProperty>& props,
                               focal::Precision precision = focal::Precision::float64) {
  const bool f32 = precision == focal::Precision::float32;
  Bytes b;
  const auto put_real = [&](double v) {
    if (f32) {
      b.put(static_cast<float>(v));
    } else {
      b.put(v);
    }
  };
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    for (int c = 0; c < 3; ++c) put_real(m.V(i, c));
    for (int c = 0; c < 3 && m.has_normals(); ++c) put_real(m.N(i, c));
    for (const auto& prop : props) {
      const double v = prop.values[i];
      switch (f32 && prop.type == focal::PropertyType::float64 ? focal::PropertyType::float32
                                                               : prop.type) {
        case focal::PropertyType::float32:
          b.put(static_cast<float>(v));
          break;
        case focal::PropertyType::float64:
          b.put(v);
          break;
        case focal::PropertyType::uint8:
          b.put(static_cast<std::uint8_t>(v));
          break;
        case focal::PropertyType::int32:
          b.put(static_cast<std::int32_t>(v));
          break;
      }
    }
  }
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    b.put(std::uint8_t{3}).put(m.F(f, 0)).put(m.F(f, 1)).put(m.F(f, 2));
  }
  return b.data;
}

std::string body_of(const std::string& ply) {
  const std::string end = "end_header\n";
  return ply.substr(ply.find(end) + end.size());
}

TEST_F(MeshIo, PlyBinaryWriteIsTheSameForAnyThreadCount) {
  // More vertices than one 8 MiB batch of the writer, so batches and blocks both vary.
  const Eigen::Index nv = 150000;
  const Eigen::Index nf = 290000;
  Mesh m;
  m.V = RowMatrixX3d::Random(nv, 3);
  m.V(5, 0) = kNaN;
  m.V(6, 1) = -kInf;
  m.V(7, 2) = -0.0;
  m.N = RowMatrixX3d::Random(nv, 3);
  m.F.resize(nf, 3);
  std::mt19937 rng(3);
  for (Eigen::Index f = 0; f < nf; ++f) {
    for (int c = 0; c < 3; ++c) m.F(f, c) = static_cast<std::int32_t>(rng() % nv);
  }
  m.face_source = Eigen::VectorXi::LinSpaced(nf, 0, static_cast<int>(nf - 1));
  std::vector<focal::VertexProperty> props = {
      {"f", Eigen::VectorXd::Random(nv) * 1e3, focal::PropertyType::float32},
      {"d", Eigen::VectorXd::Random(nv), focal::PropertyType::float64},
      {"u", Eigen::VectorXd::LinSpaced(nv, 0, 255).array().floor(), focal::PropertyType::uint8},
      {"i", Eigen::VectorXd::LinSpaced(nv, -1e6, 2e9).array().floor(), focal::PropertyType::int32}};
  const std::string expected = reference_ply_body(m, props);
  for (const bool normals : {true, false}) {
    if (!normals) m.N.resize(0, 3);
    const std::string reference = normals ? expected : reference_ply_body(m, props);
    std::string first;
    for (const int threads : {1, 2, 3}) {
      const ExecutionScope scope({.threads = threads});
      SCOPED_TRACE("threads " + std::to_string(threads));
      const fs::path p = file("out.ply");
      focal::write_ply(p, m, props, {.binary = true, .comments = {}});
      const std::string bytes = slurp(p);
      EXPECT_TRUE(body_of(bytes) == reference);
      if (first.empty()) {
        first = bytes;
      } else {
        EXPECT_TRUE(bytes == first);
      }
    }
  }
}

TEST_F(MeshIo, CurvaturePlyIsWritePlyOfTheFields) {
  const Eigen::Index nv = 20000;
  Mesh m = sample_mesh(true);
  m.V = RowMatrixX3d::Random(nv, 3);
  m.N = RowMatrixX3d::Random(nv, 3);
  focal::CurvatureResult r;
  r.k1 = Eigen::VectorXd::Random(nv);
  r.k2 = Eigen::VectorXd::Random(nv);
  r.H = Eigen::VectorXd::Random(nv);
  r.K = Eigen::VectorXd::Random(nv);
  r.K[3] = kNaN;
  r.d1 = RowMatrixX3d::Random(nv, 3);
  r.d2 = RowMatrixX3d::Random(nv, 3);
  r.residual = Eigen::VectorXd::Random(nv);
  r.point_class = focal::VectorXu8::LinSpaced(nv, 0, 5);
  std::vector<focal::VertexProperty> props;
  const auto& names = focal::curvature_field_names();
  props.push_back({names[0], r.k1, focal::PropertyType::float32});
  props.push_back({names[1], r.k2, focal::PropertyType::float32});
  props.push_back({names[2], r.H, focal::PropertyType::float32});
  props.push_back({names[3], r.K, focal::PropertyType::float32});
  for (int c = 0; c < 3; ++c) {
    props.push_back({names[4 + c], r.d1.col(c), focal::PropertyType::float32});
  }
  for (int c = 0; c < 3; ++c) {
    props.push_back({names[7 + c], r.d2.col(c), focal::PropertyType::float32});
  }
  props.push_back({names[10], r.residual, focal::PropertyType::float32});
  props.push_back({names[11], r.point_class.cast<double>(), focal::PropertyType::uint8});
  std::string comment = "focal curvature fields; class codes:";
  for (int c = 0; c <= static_cast<int>(focal::PointClass::undefined); ++c) {
    comment += " " + std::to_string(c) + "=" +
               std::string(focal::class_name(static_cast<focal::PointClass>(c)));
  }
  focal::write_ply(file("plain.ply"), m, props, {.binary = true, .comments = {comment}});
  const std::string expected = slurp(file("plain.ply"));
  for (const auto precision : {focal::Precision::float64, focal::Precision::float32}) {
    for (const bool binary : {true, false}) {
      focal::write_ply(file("plain.ply"), m, props,
                       {.binary = binary, .comments = {comment}, .precision = precision});
      for (const int threads : {1, 2}) {
        const ExecutionScope scope({.threads = threads});
        focal::write_curvature_ply(file("fields.ply"), m, r,
                                   {.binary = binary, .comments = {}, .precision = precision});
        EXPECT_TRUE(slurp(file("fields.ply")) == slurp(file("plain.ply")))
            << binary << threads << static_cast<int>(precision);
      }
    }
  }
  EXPECT_TRUE(body_of(expected) == reference_ply_body(m, props));
  r.H.resize(3);
  expect_error<focal::InvalidInput>([&] { focal::write_curvature_ply(file("bad.ply"), m, r); },
                                    {"property 'H' has 3 values but the mesh has 20000 vertices"});
}

// ---------------------------------------------------------------------------------------------
// float32 outputs (Precision::float32): every real number v is written as static_cast<float>(v)

/// m with each value rounded to float (static_cast<float>) and widened back.
RowMatrixX3d as_floats(const RowMatrixX3d& m) { return m.cast<float>().cast<double>(); }

/// The shortest text that reads back to v (std::to_chars), `nan`, `inf` or `-inf`.
std::string float_text(float v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  return {buf, std::to_chars(buf, buf + sizeof buf, v).ptr};
}

/// The bit pattern of a float, NaNs all alike (the writers write every NaN as the same `nan`).
std::uint32_t float_bits(float v) {
  return std::isnan(v) ? 0x7fc00000u : std::bit_cast<std::uint32_t>(v);
}

TEST_F(MeshIo, PlyFloat32HoldsTheFloatOfEveryValue) {
  // More vertices than one block of the binary writer; values that float rounds (1/3), that
  // underflow (1e-300) or overflow (1e300) it, a float subnormal (1e-40), NaN, infinities, -0.
  const Eigen::Index nv = 70000;
  const Eigen::Index nf = 1000;
  Mesh m;
  m.V = RowMatrixX3d::Random(nv, 3) * 1e3;
  m.V.row(0) << 1.0 / 3.0, 1e-300, 1e300;
  m.V.row(1) << kNaN, -kInf, -0.0;
  m.N = RowMatrixX3d::Random(nv, 3);
  m.N.row(2) << -1e300, 1e-40, kNaN;
  m.F.resize(nf, 3);
  std::mt19937 rng(5);
  for (Eigen::Index f = 0; f < nf; ++f) {
    for (int c = 0; c < 3; ++c) m.F(f, c) = static_cast<std::int32_t>(rng() % nv);
  }
  m.face_source = Eigen::VectorXi::LinSpaced(nf, 0, static_cast<int>(nf - 1));
  Eigen::VectorXd d = Eigen::VectorXd::Random(nv);
  d.head(3) << kNaN, 1e300, -1e-300;
  const std::vector<focal::VertexProperty> props = {
      {"f", Eigen::VectorXd::Random(nv) * 1e3, focal::PropertyType::float32},
      {"d", d, focal::PropertyType::float64},
      {"u", Eigen::VectorXd::LinSpaced(nv, 0, 255).array().floor(), focal::PropertyType::uint8},
      {"i", Eigen::VectorXd::LinSpaced(nv, -1e6, 2e9).array().floor(), focal::PropertyType::int32}};
  for (const bool normals : {true, false}) {
    if (!normals) m.N.resize(0, 3);
    const std::string body = reference_ply_body(m, props, focal::Precision::float32);
    std::string expected_header = "property float x\nproperty float y\nproperty float z\n";
    if (normals) expected_header += "property float nx\nproperty float ny\nproperty float nz\n";
    expected_header +=
        "property float f\nproperty float d\nproperty uchar u\nproperty int i\nelement face";
    for (const int threads : {1, 2}) {
      const ExecutionScope scope({.threads = threads});
      SCOPED_TRACE("normals " + std::to_string(normals) + ", threads " + std::to_string(threads));
      const fs::path p = file("f32.ply");
      focal::write_ply(p, m, props,
                       {.binary = true, .comments = {}, .precision = focal::Precision::float32});
      const std::string bytes = slurp(p);
      const std::string header = bytes.substr(0, bytes.find("end_header\n"));
      EXPECT_NE(header.find(expected_header), std::string::npos) << header;
      EXPECT_EQ(header.find("double"), std::string::npos) << header;
      EXPECT_TRUE(body_of(bytes) == body);
      const Mesh r = focal::read_mesh(p);
      expect_same(as_floats(m.V), r.V);
      EXPECT_EQ(r.has_normals(), normals);
      if (normals) expect_same(as_floats(m.N), r.N);
      EXPECT_TRUE(r.F == m.F);
    }
  }
  // The default is unchanged: doubles, bit for bit.
  focal::write_ply(file("f64.ply"), m, props);
  EXPECT_TRUE(body_of(slurp(file("f64.ply"))) == reference_ply_body(m, props));
  EXPECT_NE(slurp(file("f64.ply")).find("property double x\n"), std::string::npos);
}

TEST_F(MeshIo, PlyAsciiFloat32IsTheShortestTextOfTheFloat) {
  const Mesh m = sample_mesh(true);
  Eigen::VectorXd d(5);
  d << 1.0 / 3.0, kNaN, kInf, 0.1, -2.5;
  const std::vector<focal::VertexProperty> props = {{"d", d, focal::PropertyType::float64}};
  const fs::path p = file("f32a.ply");
  focal::write_ply(p, m, props,
                   {.binary = false, .comments = {}, .precision = focal::Precision::float32});
  const std::string text = slurp(p);
  EXPECT_NE(text.find("property float x\n"), std::string::npos);
  EXPECT_NE(text.find("property float nz\nproperty float d\n"), std::string::npos);
  EXPECT_EQ(text.find("double"), std::string::npos);
  // 1e-300 underflows to 0; 1/3 is 0.3333333432674408 as a float, written 0.33333334.
  EXPECT_NE(text.find("end_header\n"
                      "0.1 -2.5 0 0 0 1 0.33333334\n"
                      "0.33333334 0.6666667 7 0.6 0.8 0 nan\n"
                      "-0 5e+10 3.1415927 -1 0 0 inf\n"),
            std::string::npos)
      << text;
  // A text reader parses to the double nearest the decimal, which rounds to the float written.
  const Mesh r = focal::read_mesh(p);
  expect_same(as_floats(m.V), as_floats(r.V));
  expect_same(as_floats(m.N), as_floats(r.N));
}

// Text files read back as the double nearest each decimal written, which rounds to the float
// (binary PLY: the float itself).
TEST_F(MeshIo, TextMeshesFloat32ReadBackAsTheFloats) {
  const Mesh m = sample_mesh(true);
  for (const char* name : {"m.obj", "m.off", "m.xyz", "m.ply"}) {
    SCOPED_TRACE(name);
    focal::write_mesh(file(std::string("f64-") + name), m);
    focal::write_mesh(file(name), m, {.precision = focal::Precision::float32});
    const Mesh r = focal::read_mesh(file(name));
    const bool binary = std::string_view(name) == "m.ply";
    expect_same(as_floats(m.V), binary ? r.V : as_floats(r.V));
    expect_same(as_floats(m.N), binary ? r.N : as_floats(r.N));
    EXPECT_LT(fs::file_size(file(name)), fs::file_size(file(std::string("f64-") + name)));
  }
  EXPECT_EQ(slurp(file("m.obj")).rfind("v 0.1 -2.5 0\nv 0.33333334 0.6666667 7\n", 0), 0u);
  EXPECT_EQ(slurp(file("m.off")).rfind("NOFF\n5 4 0\n0.1 -2.5 0 0 0 1\n", 0), 0u);
  EXPECT_EQ(slurp(file("m.xyz")).rfind("0.1 -2.5 0 0 0 1\n0.33333334 0.6666667 7 0.6 0.8 0\n", 0),
            0u);
}

TEST_F(MeshIo, CurvatureCsvFloat32HoldsTheFloatOfEveryValue) {
  const Eigen::Index nv = 2048 * 16 + 333;  // more than one batch of the CSV writer
  focal::CurvatureResult r;
  r.k1 = Eigen::VectorXd::Random(nv) * 10;
  r.k2 = Eigen::VectorXd::Random(nv);
  r.H = Eigen::VectorXd::Random(nv);
  r.K = Eigen::VectorXd::Random(nv) * 1e-3;
  r.d1 = RowMatrixX3d::Random(nv, 3);
  r.d2 = RowMatrixX3d::Random(nv, 3);
  r.residual = Eigen::VectorXd::Random(nv).cwiseAbs() * 1e-9;
  r.point_class = focal::VectorXu8::LinSpaced(nv, 0, 4);
  // Undefined rows: every value NaN, class undefined, as the estimators leave them.
  for (const Eigen::Index i : {Eigen::Index{7}, nv - 1}) {
    r.k1[i] = r.k2[i] = r.H[i] = r.K[i] = r.residual[i] = kNaN;
    r.d1.row(i).setConstant(kNaN);
    r.d2.row(i).setConstant(kNaN);
    r.point_class[i] = static_cast<std::uint8_t>(focal::PointClass::undefined);
  }
  r.k1[8] = kInf;
  r.k2[8] = -kInf;
  r.H[9] = 1e300;   // beyond float: inf
  r.K[9] = 1e-300;  // below float: 0
  r.residual[10] = -0.0;
  focal::VectorXu8 crease = focal::VectorXu8::Zero(nv);
  crease.tail(100).setOnes();
  const auto& names = focal::curvature_field_names();
  const std::vector<const double*> columns = {r.k1.data(),     r.k2.data(),      r.H.data(),
                                              r.K.data(),      r.d1.data(),      r.d1.data() + 1,
                                              r.d1.data() + 2, r.d2.data(),      r.d2.data() + 1,
                                              r.d2.data() + 2, r.residual.data()};
  const std::vector<Eigen::Index> strides = {1, 1, 1, 1, 3, 3, 3, 3, 3, 3, 1};

  focal::write_curvature_csv(file("f64.csv"), r, crease);
  focal::write_curvature_csv(file("f64-options.csv"), r, crease, focal::WriteOptions{});
  EXPECT_TRUE(slurp(file("f64.csv")) == slurp(file("f64-options.csv")));
  const std::string doubles = slurp(file("f64.csv"));
  std::string first;
  for (const int threads : {1, 2, 3}) {
    const ExecutionScope scope({.threads = threads});
    focal::write_curvature_csv(file("f32.csv"), r, crease,
                               {.precision = focal::Precision::float32});
    const std::string text = slurp(file("f32.csv"));
    if (first.empty()) first = text;
    EXPECT_TRUE(text == first) << threads << " threads";
  }
  EXPECT_LT(first.size(), doubles.size() * 2 / 3);
  std::istringstream f32(first);
  std::istringstream f64(doubles);
  std::string line32;
  std::string line64;
  ASSERT_TRUE(std::getline(f32, line32) && std::getline(f64, line64));
  EXPECT_EQ(line32, line64);  // the header
  EXPECT_EQ(line32, "k1,k2,H,K,d1x,d1y,d1z,d2x,d2y,d2z,residual,class,crease");
  Eigen::Index row = 0;
  int mismatches = 0;
  while (std::getline(f32, line32) && std::getline(f64, line64)) {
    std::vector<std::string> cells;
    std::stringstream s(line32);
    for (std::string cell; std::getline(s, cell, ',');) cells.push_back(cell);
    ASSERT_EQ(cells.size(), 13u) << line32;
    for (std::size_t c = 0; c < 11; ++c) {
      float v = 0;
      const char* end = cells[c].data() + cells[c].size();
      const auto [ptr, ec] = std::from_chars(cells[c].data(), end, v);
      const float want = static_cast<float>(columns[c][row * strides[c]]);
      if (ec != std::errc() || ptr != end || float_bits(v) != float_bits(want) ||
          cells[c] != float_text(want)) {
        if (++mismatches <= 5) {
          ADD_FAILURE() << "row " << row << " " << names[c] << ": '" << cells[c] << "', want "
                        << want;
        }
      }
    }
    // class and crease: the words and flags of the double file.
    const auto class_and_crease = [](const std::string& line) {
      std::size_t at = 0;
      for (int commas = 0; commas < 11; ++commas) at = line.find(',', at) + 1;
      return line.substr(at);
    };
    EXPECT_EQ(class_and_crease(line32), class_and_crease(line64)) << row;
    ++row;
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(row, nv);
  EXPECT_FALSE(std::getline(f64, line64));
  // Undefined rows and infinities are written as the double file writes them.
  EXPECT_NE(first.find("\nnan,nan,nan,nan,nan,nan,nan,nan,nan,nan,nan,undefined,0\n"),
            std::string::npos);
  EXPECT_NE(first.find("\ninf,-inf,"), std::string::npos);
}

TEST_F(MeshIo, FocalMeshFloat32KeepsTheFlags) {
  focal::FocalMeshes meshes;
  for (focal::FocalMesh* g : {&meshes.gamma1, &meshes.gamma2}) {
    g->mesh.V = rows({{1.0 / 3.0, 0, 0}, {0, 1e6 + 0.1, 0}, {0, 0, 0.1}});
    g->mesh.F.resize(1, 3);
    g->mesh.F << 0, 1, 2;
    g->flag.resize(3);
    g->flag << 0, 1, 2;  // finite, infinite (clamped), undefined (the base vertex)
  }
  focal::write_focal_meshes_ply(
      file("g.focal1.ply"), file("g.focal2.ply"), meshes,
      {.binary = true, .comments = {}, .precision = focal::Precision::float32});
  const std::vector<focal::VertexProperty> flag = {
      {"focal_flag", meshes.gamma1.flag.cast<double>(), focal::PropertyType::uint8}};
  for (const char* name : {"g.focal1.ply", "g.focal2.ply"}) {
    const std::string bytes = slurp(file(name));
    EXPECT_NE(bytes.find("property float x\nproperty float y\nproperty float z\n"
                         "property uchar focal_flag\n"),
              std::string::npos);
    EXPECT_TRUE(body_of(bytes) ==
                reference_ply_body(meshes.gamma1.mesh, flag, focal::Precision::float32));
    expect_same(as_floats(meshes.gamma1.mesh.V), focal::read_mesh(file(name)).V);
  }
}

// ---------------------------------------------------------------------------------------------
// Speed (run on demand: mesh_io_test --gtest_also_run_disabled_tests --gtest_filter='*Speed*')

TEST_F(MeshIo, DISABLED_SpeedBinaryPly1MVertices2MFaces) {
  const Eigen::Index nv = 1000000;
  const Eigen::Index nf = 2000000;
  Mesh m;
  m.V = RowMatrixX3d::Random(nv, 3);
  m.N = RowMatrixX3d::Random(nv, 3);
  m.F.resize(nf, 3);
  std::mt19937 rng(1);
  for (Eigen::Index f = 0; f < nf; ++f) {
    for (int c = 0; c < 3; ++c) m.F(f, c) = static_cast<std::int32_t>(rng() % nv);
  }
  m.face_source = Eigen::VectorXi::LinSpaced(nf, 0, static_cast<int>(nf - 1));
  for (const bool binary : {true, false}) {
    const fs::path p = file(binary ? "big.ply" : "big_ascii.ply");
    auto t0 = std::chrono::steady_clock::now();
    focal::write_ply(p, m, {}, binary ? focal::PlyWriteOptions{} : ascii_options());
    auto t1 = std::chrono::steady_clock::now();
    double best = 1e9;
    for (int run = 0; run < 3; ++run) {
      const auto r0 = std::chrono::steady_clock::now();
      const Mesh r = focal::read_mesh(p);
      best = std::min(best,
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count());
      if (run == 0) expect_same_mesh(m, r);
    }
    std::printf(
        "%s PLY, %lld vertices (x y z nx ny nz double), %lld faces, %.1f MB: write %.3f s, "
        "read %.3f s (best of 3)\n",
        binary ? "binary" : "ascii", static_cast<long long>(nv), static_cast<long long>(nf),
        static_cast<double>(fs::file_size(p)) / 1e6, std::chrono::duration<double>(t1 - t0).count(),
        best);
    if (binary) {
      EXPECT_LT(best, 1.0);
    }
  }
}

}  // namespace

// Issue 13 item 7: MeshLab's NCOFF (vcglib's exporter: colour, then normal), Geomview's CNOFF
// (normal, then colour), with texture coordinates too; other prefixes are refused by name.
TEST_F(MeshIo, OffColourAndNormalInMeshLabAndGeomviewOrder) {
  const std::string faces = "3 0 1 2\n";
  const Mesh meshlab = focal::read_mesh(write("nc.off",
                                              "NCOFF\n3 1 0\n"
                                              "0 0 0 255 0 0 255 0 0.6 0.8 \n"
                                              "1 0 0 9 9 9 255 1 0 0\n"
                                              "0 1 0 9 9 9 255 0 1 0\n" +
                                                  faces));
  ASSERT_TRUE(meshlab.has_normals());
  expect_same(meshlab.N, rows({{0, 0.6, 0.8}, {1, 0, 0}, {0, 1, 0}}));
  const Mesh geomview = focal::read_mesh(write("cn.off",
                                               "CNOFF\n3 1 0\n"
                                               "0 0 0 0 0.6 0.8 0.5 0.5 0.5 1\n"
                                               "1 0 0 1 0 0 0.5 0.5 0.5 1\n"
                                               "0 1 0 0 1 0 0.5 0.5 0.5 1\n" +
                                                   faces));
  expect_same(geomview.N, meshlab.N);
  const Mesh textured = focal::read_mesh(write("ncst.off",
                                               "NCSTOFF\n3 1 0\n"
                                               "0 0 0 1 2 3 0 0.6 0.8 0.25 0.75\n"
                                               "1 0 0 1 2 3 1 0 0 0.25 0.75\n"
                                               "0 1 0 1 2 3 0 1 0 0.25 0.75\n" +
                                                   faces));
  expect_same(textured.N, meshlab.N);
  expect_io_error(write("bad.off", "CXOFF\n3 1 0\n"),
                  {"line 1", "unsupported OFF variant 'CXOFF'"});
  expect_io_error(write("long.off", "NCOFF\n1 0 0\n0 0 0 1 2 3 4 5 0 0 1\n"),
                  {"line 3", "vertex 0: expected 6 to 10 numbers"});
}

// Issue 13 item 7: meshio writes int64 / uint64 properties; indices are range-checked.
TEST_F(MeshIo, Ply64BitIntegersAreReadWithRangeChecks) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty int64 x\nproperty uint64 y\n"
      "property double z\nelement face 1\nproperty list uint8 int64 vertex_indices\nend_header\n";
  const Mesh m = focal::read_mesh(write("i64.ply", header + "0 0 0\n1 0 0\n-2 5 0\n3 0 1 2\n"));
  expect_same(m.V, rows({{0, 0, 0}, {1, 0, 0}, {-2, 5, 0}}));
  expect_faces(m, {{0, 1, 2}}, {0});
  expect_io_error(write("far.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 4294967296\n"),
                  {"face 0 refers to vertex 4294967296 but there are 3 vertices"});

  // Binary: an index of 2^64 - 1 stays out of range (saturated), never wraps to a valid one.
  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uint64 uint64 vertex_indices\nend_header\n";
  const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  bin.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  const std::uint64_t face[4] = {3, 0, 1, ~std::uint64_t{0}};
  bin.append(reinterpret_cast<const char*>(face), sizeof face);
  expect_io_error(write("u64.ply", bin), {"face 0 refers to vertex 9223372036854775807"});
  // A 64-bit list length the file cannot hold is a truncation, not an allocation.
  std::string huge = bin.substr(0, bin.size() - sizeof face);
  const std::uint64_t length = std::uint64_t{1} << 62;
  huge.append(reinterpret_cast<const char*>(&length), sizeof length);
  expect_io_error(write("huge.ply", huge), {"file ends inside face 0 of 1"});
}

// Issue 13 item 7: triangle strips, -1 restarting a strip, every other triangle reversed so
// that all keep the first one's orientation, joining (repeated-corner) triangles left out.
TEST_F(MeshIo, PlyTristripsBecomeTriangles) {
  const std::string vertices = "0 0 0\n1 0 0\n2 0 0\n0 1 0\n1 1 0\n2 1 0\n";
  const Mesh m = focal::read_mesh(
      write("strip.ply",
            "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
            "property float z\nelement tristrips 1\nproperty list int int vertex_indices\n"
            "end_header\n" +
                vertices + "9 3 0 4 1 1 -1 4 1 5\n"));
  expect_faces(m, {{3, 0, 4}, {4, 0, 1}, {4, 1, 5}}, {0, 0, 0});
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {  // all counter-clockwise seen from +z
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    const Eigen::Vector3d u = b - a, v = c - a;
    EXPECT_GT(u.x() * v.y() - u.y() * v.x(), 0.0) << "triangle " << f;
  }
  expect_io_error(
      write("bad_strip.ply",
            "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
            "property float z\nelement tristrips 1\nproperty list int int vertex_indices\n"
            "end_header\n" +
                vertices + "4 0 1 2 -2\n"),
      {"line 16", "tristrips 0 refers to vertex -2 but there are 6 vertices"});
}

// Issue 13 item 8: a binary PLY whose header names the other byte order says so.
TEST_F(MeshIo, PlyIndicesInTheOtherByteOrderHintAtIt) {
  std::string bin =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  bin.append(36, '\0');                                                    // nine big-endian zeros
  const unsigned char face[13] = {3, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0};  // little endian
  bin.append(reinterpret_cast<const char*>(face), sizeof face);
  expect_io_error(write("order.ply", bin), {"face 0 refers to vertex 16777216",
                                            "wrong byte order? the header says "
                                            "binary_big_endian"});
}

// Issue 13 item 8: numbers below the smallest double underflow as in C; old MSVC's "1.#QNAN"
// is an error naming line and token, not a number cut short by a comment; trailing blanks on
// PLY header lines are fine.
TEST_F(MeshIo, UnderflowMsvcNanAndTrailingBlanks) {
  const Mesh m = focal::read_mesh(write("tiny.obj", "v 1e-400 -1e-320 0 # comment\n"));
  EXPECT_EQ(m.V(0, 0), 0.0);
  EXPECT_EQ(m.V(0, 1), -1e-320);  // a subnormal, kept
  expect_io_error(write("msvc.obj", "v 0 0 0\nv 0 0 1.#QNAN\n"),
                  {"line 2", "'1.#QNAN' is not a number"});
  expect_io_error(write("msvc.off", "OFF\n1 0 0\n0 0 1.#INF\n"), {"line 3", "'1.#INF'"});
  expect_io_error(write("huge.obj", "v 0 0 1e400\n"), {"line 1", "'1e400' is not a number"});
  const Mesh p = focal::read_mesh(
      write("blank.ply",
            "ply \nformat ascii 1.0 \nelement vertex 1  \nproperty float x\t\nproperty float y\n"
            "property float z\nend_header  \n1 2 3\n"));
  expect_same(p.V, rows({{1, 2, 3}}));
}

// The parallel text readers (issue 19: OBJ, OFF, ascii PLY, ascii STL): a file read in runs of
// lines on any number of threads gives the serial reader's Mesh bit for bit, and its errors word
// for word; the STL weld gives the same vertices on any number of threads.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "focal/core/error.h"
#include "io/format_readers.h"
#include "io/text_scan.h"

namespace focal {
namespace {

constexpr int kRows = 60;  // grid of kRows x kCols vertices
constexpr int kCols = 60;
constexpr std::size_t kRunBytes[] = {97, 4096, 65536};  // 1 to 2 lines, ~100 lines, ~4 runs
constexpr int kThreads[] = {1, 2, 3, 8};

std::string number(double value) {
  char buf[64];
  const auto end = std::to_chars(buf, buf + sizeof buf, value).ptr;
  return {buf, end};
}

int vertex(int r, int c) { return r * kCols + c + 1; }  // 1-based, as OBJ writes it

/// Corner k of a face in one of the four forms; every 7th vertex's corner names a neighbour's
/// normal so that some vertices average two normals.
std::string corner(int v, int form) {
  const std::string s = std::to_string(v);
  const std::string n = std::to_string(v % 7 == 0 && v > 1 ? v - 1 : v);
  switch (form % 4) {
    case 0:
      return s;
    case 1:
      return s + "/" + s;
    case 2:
      return s + "//" + n;
    default:
      return s + "/" + s + "/" + n;
  }
}

/// A row r of faces below grid row r + 1: quads, two triangles, or one hexagon over two cells.
void append_faces(std::string& out, int r) {
  for (int c = 0; c + 1 < kCols; ++c) {
    const int a = vertex(r, c), b = vertex(r, c + 1), d = vertex(r + 1, c + 1),
              e = vertex(r + 1, c);
    const int form = r + c;
    if (c % 10 == 3 && c + 2 < kCols) {
      out += "f " + corner(a, form) + " " + corner(b, form) + " " + corner(vertex(r, c + 2), form) +
             " " + corner(vertex(r + 1, c + 2), form) + " " + corner(d, form) + " " +
             corner(e, form) + "\n";
      ++c;
    } else if (c % 9 == 0) {
      out += "f\t" + corner(a, form) + " " + corner(b, form) + "  " + corner(d, form) + "\r\n";
      out += "f " + corner(a, form) + " " + corner(d, form) + " " + corner(e, form) + " # tri\n";
    } else {
      out += "f " + corner(a, form) + " " + corner(b, form) + " " + corner(d, form) + " " +
             corner(e, form) + (c % 5 == 0 ? "\r\n" : "\n");
    }
  }
}

/// A few thousand vertices in every form the reader meets: comments, blank lines, CRLF, tabs,
/// `v` with w and colours, vt and vn, ignored statements, faces before the vertices they name
/// (forward references), quads, hexagons, and no line break at the end.
std::string obj_text() {
  std::string out = "# made by text_readers_test\nmtllib none.mtl\no grid\n\n";
  out += "f " + std::to_string(vertex(kRows - 1, 0)) + " " + std::to_string(vertex(kRows - 1, 1)) +
         " " + std::to_string(vertex(kRows - 2, 0)) + "\n";  // forward reference
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      const int i = r * kCols + c;
      const double x = 0.1 * c + 1e-7 * i, y = -0.03 * r / 7.0, z = 1.0 / (1.0 + i);
      if (i % 5 == 0) {
        out += "v\t" + number(x) + "  \t" + number(y) + "   " + number(z) + "\r\n";
      } else if (i % 13 == 0) {
        out += "v " + number(x) + " " + number(y) + " " + number(z) + " 1.0 0.5 0.25 0.125\n";
      } else if (i % 11 == 0) {
        out += "v +" + number(x) + " " + number(y) + " " + number(z) + " # vertex\n";
      } else {
        out += "v " + number(x) + " " + number(y) + " " + number(z) + "\n";
      }
      out += "vt " + number(x) + " " + number(z) + "\n";
      out += "vn " + number(z) + " " + number(-x) + " " + number(y) + (i % 3 ? "\n" : "\r\n");
      if (i % 97 == 0) out += "\n   \n# a comment line\r\n";
    }
    if (r % 8 == 0) out += "g row" + std::to_string(r) + "\ns 1\nusemtl m\n";
    if (r > 0) append_faces(out, r - 1);
  }
  out.pop_back();  // no line break after the last face
  return out;
}

template <class Matrix>
bool same_bits(const Matrix& a, const Matrix& b) {
  // An empty matrix has no data pointer, and memcmp must not be given a null one.
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         (a.size() == 0 ||
          std::memcmp(a.data(), b.data(), sizeof(*a.data()) * static_cast<std::size_t>(a.size())) ==
              0);
}

void expect_same_mesh(const Mesh& a, const Mesh& b) {
  EXPECT_TRUE(same_bits(a.V, b.V));
  EXPECT_TRUE(same_bits(a.N, b.N));
  EXPECT_TRUE(same_bits(a.F, b.F));
  EXPECT_TRUE(same_bits(a.face_source, b.face_source));
}

/// A reader on text in memory with threads and run size (parse_obj, parse_off, parse_ply,
/// parse_stl), and its parallel read alone (parse_X_in_chunks: nothing where it falls back).
using Parser = Mesh (*)(const std::filesystem::path&, std::string_view, int, std::size_t);
using ChunkParser = std::optional<Mesh> (*)(const std::filesystem::path&, std::string_view, int,
                                            std::size_t);

/// The serial read of `text`.
Mesh serial_read(Parser parse, const std::filesystem::path& path, std::string_view text) {
  return parse(path, text, 1, io_detail::kTextChunkBytes);
}

/// Every thread count and run size gives `serial` bit for bit, and the parallel read has run (not
/// fallen back) wherever there are threads to run it.
void expect_serial_mesh_everywhere(Parser parse, ChunkParser in_chunks,
                                   const std::filesystem::path& path, std::string_view text,
                                   const Mesh& serial) {
  for (const std::size_t run : kRunBytes) {
    for (const int threads : kThreads) {
      SCOPED_TRACE("run bytes " + std::to_string(run) + ", threads " + std::to_string(threads));
      expect_same_mesh(parse(path, text, threads, run), serial);
      const std::optional<Mesh> parallel = in_chunks(path, text, threads, run);
      ASSERT_EQ(parallel.has_value(), threads > 1);
      if (parallel) expect_same_mesh(*parallel, serial);
    }
  }
}

/// The message of the IoError that `parse` throws on `text` with these threads and runs.
std::string error_of(Parser parse, const std::filesystem::path& path, std::string_view text,
                     int threads, std::size_t run_bytes) {
  try {
    (void)parse(path, text, threads, run_bytes);
  } catch (const IoError& e) {
    return e.what();
  }
  return "no error";
}

/// The serial read's error on each broken text, after checking that every thread count and run
/// size gives it word for word.
std::vector<std::string> serial_errors_everywhere(Parser parse, const std::filesystem::path& path,
                                                  const std::vector<std::string>& broken) {
  std::vector<std::string> errors;
  for (std::size_t b = 0; b < broken.size(); ++b) {
    errors.push_back(error_of(parse, path, broken[b], 1, io_detail::kTextChunkBytes));
    for (const std::size_t run : kRunBytes) {
      for (const int threads : kThreads) {
        EXPECT_EQ(error_of(parse, path, broken[b], threads, run), errors.back())
            << "case " << b << ", run bytes " << run << ", threads " << threads;
      }
    }
  }
  return errors;
}

const std::filesystem::path kPath = "grid.obj";

/// Offset of the start of `line` (1-based).
std::size_t line_start(const std::string& text, std::size_t line) {
  std::size_t begin = 0;
  for (std::size_t l = 1; l < line; ++l) begin = text.find('\n', begin) + 1;
  return begin;
}

/// `text` with `line` (1-based) replaced.
std::string with_line(const std::string& text, std::size_t line, const std::string& replacement) {
  const std::size_t begin = line_start(text, line);
  const std::size_t end = text.find('\n', begin);
  return text.substr(0, begin) + replacement + text.substr(end);
}

/// The 1-based line of the first line starting with `prefix` after half the text (after `from`,
/// if given).
std::size_t line_in_the_middle(const std::string& text, std::string_view prefix,
                               std::size_t from = std::string::npos) {
  if (from == std::string::npos) from = text.size() / 2;
  std::size_t pos = text.find(std::string("\n") + std::string(prefix), from) + 1;
  return static_cast<std::size_t>(
             std::count(text.begin(), text.begin() + static_cast<long>(pos), '\n')) +
         1;
}

TEST(ObjParallelRead, EveryThreadCountAndRunSizeGivesTheSerialMeshBitForBit) {
  const std::string text = obj_text();
  const Mesh serial = serial_read(static_cast<Parser>(&io_detail::parse_obj), kPath, text);
  ASSERT_EQ(serial.V.rows(), kRows * kCols);
  // Per row of cells: 6 hexagons (4 triangles each) covering 12 cells, 7 cells split in two, the
  // remaining 40 cells quads (2 triangles each); plus the forward-referencing triangle.
  EXPECT_EQ(serial.F.rows(), 1 + (kRows - 1) * (6 * 4 + 7 * 2 + 40 * 2));
  EXPECT_EQ(serial.V(1, 0), 0.1 + 1e-7);
  EXPECT_EQ(serial.V(kRows * kCols - 1, 2), 1.0 / kRows / kCols);
  ASSERT_EQ(serial.N.rows(), serial.V.rows());
  expect_serial_mesh_everywhere(static_cast<Parser>(&io_detail::parse_obj),
                                &io_detail::parse_obj_in_chunks, kPath, text, serial);
}

TEST(ObjParallelRead, ErrorsInTheMiddleOfARunAreTheSerialReadersWordForWord) {
  const std::string text = obj_text();
  const std::size_t v_line = line_in_the_middle(text, "v ");
  const std::size_t f_line = line_in_the_middle(text, "f ");
  const std::vector<std::string> broken = {
      with_line(text, v_line, "v 1.0 2.0x 3.0"),
      with_line(text, v_line, "v 1.0 2.0"),
      with_line(text, f_line, "f 1 2"),
      with_line(text, f_line, "f 1 2 -99999"),
      with_line(text, f_line, "f 1 2/0 3"),
      with_line(text, f_line, "f 1 2 99999"),        // out of range: found after the parallel read
      with_line(text, f_line, "f 1//2 2//99999 3"),  // so is a normal out of range
      with_line(text, v_line, std::string("v 1 2 3\x01")),
  };
  const std::vector<std::string> where = {
      "line " + std::to_string(v_line) + ": '2.0x' is not a number",
      "line " + std::to_string(v_line) + ": expected 3 coordinates, got 2",
      "line " + std::to_string(f_line) + ": face ",
      "line " + std::to_string(f_line) + ": face ",
      "line " + std::to_string(f_line) + ": '0' is not a valid texture coordinate index",
      "line " + std::to_string(f_line) + ": face ",
      "line " + std::to_string(f_line) + ": face ",
      "byte offset ",
  };
  const std::vector<std::string> serial =
      serial_errors_everywhere(static_cast<Parser>(&io_detail::parse_obj), kPath, broken);
  for (std::size_t b = 0; b < broken.size(); ++b) {
    EXPECT_NE(serial[b].find(where[b]), std::string::npos) << serial[b];
  }
}

TEST(ObjParallelRead, RelativeIndicesFallBackToTheSerialRead) {
  const std::string text = obj_text();
  const std::size_t line = line_in_the_middle(text, "f ");
  const std::string relative = with_line(text, line, "f -1 -2/-3 -3//-4");
  const Mesh serial = serial_read(static_cast<Parser>(&io_detail::parse_obj), kPath, relative);
  EXPECT_FALSE(io_detail::parse_obj_in_chunks(kPath, relative, 8, 4096).has_value());
  for (const int threads : kThreads) {
    expect_same_mesh(io_detail::parse_obj(kPath, relative, threads, 4096), serial);
  }
  // The relative face names the last three vertices read before its line.
  const std::string before = text.substr(0, line_start(text, line));
  int vertices = 0;
  for (std::size_t pos = before.find("\nv"); pos != std::string::npos;
       pos = before.find("\nv", pos + 1)) {
    vertices += before[pos + 2] == ' ' || before[pos + 2] == '\t';
  }
  bool found = false;
  for (Eigen::Index f = 0; f < serial.F.rows(); ++f) {
    found = found || (serial.F(f, 0) == vertices - 1 && serial.F(f, 1) == vertices - 2 &&
                      serial.F(f, 2) == vertices - 3);
  }
  EXPECT_TRUE(found) << vertices << " vertices before line " << line;
}

TEST(ObjParallelRead, LineAlignedCutsEndRunsAfterALineBreak) {
  const std::string text = "v 1 2 3\nv 4 5 6\r\n\nf 1 2 3";
  // A cut follows the first '\n' at least the run size past the previous cut.
  EXPECT_EQ(io_detail::line_aligned_cuts(text, 1), (std::vector<std::size_t>{0, 8, 17, 25}));
  EXPECT_EQ(io_detail::line_aligned_cuts(text, 9), (std::vector<std::size_t>{0, 17, 25}));
  EXPECT_EQ(io_detail::line_aligned_cuts(text, 100), (std::vector<std::size_t>{0, 25}));
}

// OFF: the header is read serially, the vertex and face lines in runs.

const std::filesystem::path kOffPath = "grid.off";

/// An OFF (NOFF when `normals`) of the grid: comments and blank lines between the header's lines
/// and the elements, CRLF, tabs, faces with colours, quads, triangles and hexagons, a comment
/// after the last face.
std::string off_text(bool normals) {
  std::string vertices, faces;
  int face_count = 0;
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      const int i = r * kCols + c;
      const double x = 0.1 * c + 1e-7 * i, y = -0.03 * r / 7.0, z = 1.0 / (1.0 + i);
      // Appended piece by piece: GCC 12 warns (-Wrestrict, falsely) on a chain of + here.
      if (i % 5 == 0) vertices += '\t';
      vertices += number(x);
      vertices += i % 3 ? " " : " \t ";
      vertices += number(y);
      vertices += ' ';
      vertices += number(z);
      if (normals) {
        for (const double n : {z, -x, y}) {
          vertices += ' ';
          vertices += number(n);
        }
      }
      vertices += i % 7 == 0 ? " # vertex\r\n" : "\n";
      if (i % 97 == 0) vertices += "\n  \n# comment\n";
    }
  }
  const auto v = [](int r, int c) { return std::to_string(r * kCols + c); };
  for (int r = 0; r + 1 < kRows; ++r) {
    for (int c = 0; c + 1 < kCols; ++c) {
      if (c % 10 == 3 && c + 2 < kCols) {
        faces += "6 " + v(r, c) + " " + v(r, c + 1) + " " + v(r, c + 2) + " " + v(r + 1, c + 2) +
                 " " + v(r + 1, c + 1) + " " + v(r + 1, c) + "\n";
        ++c;
        ++face_count;
      } else if (c % 9 == 0) {
        faces += "3\t" + v(r, c) + " " + v(r, c + 1) + "  " + v(r + 1, c + 1) + " 255 0 0\r\n";
        faces += "3 " + v(r, c) + " " + v(r + 1, c + 1) + " " + v(r + 1, c) + " # tri\n";
        face_count += 2;
      } else {
        faces += "4 " + v(r, c) + " " + v(r, c + 1) + " " + v(r + 1, c + 1) + " " + v(r + 1, c) +
                 (c % 5 == 0 ? "\r\n" : "\n");
        ++face_count;
      }
    }
    if (r % 13 == 0) faces += "\n# row\n";
  }
  return std::string(normals ? "NOFF" : "OFF") + "\n# made by text_readers_test\n\n" +
         std::to_string(kRows * kCols) + " " + std::to_string(face_count) + " 0\n" + vertices +
         faces + "# end\n";
}

TEST(OffParallelRead, EveryThreadCountAndRunSizeGivesTheSerialMeshBitForBit) {
  for (const bool normals : {false, true}) {
    const std::string text = off_text(normals);
    const Mesh serial = serial_read(static_cast<Parser>(&io_detail::parse_off), kOffPath, text);
    ASSERT_EQ(serial.V.rows(), kRows * kCols);
    EXPECT_EQ(serial.F.rows(), (kRows - 1) * (6 * 4 + 7 * 2 + 40 * 2));
    EXPECT_EQ(serial.V(1, 0), 0.1 + 1e-7);
    EXPECT_EQ(serial.V(kRows * kCols - 1, 2), 1.0 / kRows / kCols);
    EXPECT_EQ(serial.N.rows(), normals ? serial.V.rows() : 0);
    SCOPED_TRACE("normals " + std::to_string(normals));
    expect_serial_mesh_everywhere(static_cast<Parser>(&io_detail::parse_off),
                                  &io_detail::parse_off_in_chunks, kOffPath, text, serial);
  }
}

TEST(OffParallelRead, ErrorsInTheMiddleOfARunAreTheSerialReadersWordForWord) {
  const std::string text = off_text(true);
  const std::size_t v_line = line_in_the_middle(text.substr(0, text.find("\n4 ")), "0.");
  const std::size_t f_line = line_in_the_middle(text, "4 ");
  const std::string cut = text.substr(0, line_start(text, f_line));  // ends inside the faces
  const std::vector<std::string> broken = {
      with_line(text, v_line, "1.0 2.0x 3.0 0 0 1"),
      with_line(text, v_line, "1.0 2.0 3.0 0 0"),
      with_line(text, f_line, "2 1 2"),
      with_line(text, f_line, "4 1 2 3"),
      with_line(text, f_line, "4 1 2 3 99999"),
      with_line(text, f_line, "x 1 2 3"),
      cut,
  };
  const std::vector<std::string> where = {
      "line " + std::to_string(v_line) + ": '2.0x' is not a number",
      "line " + std::to_string(v_line) + ": vertex ",
      "line " + std::to_string(f_line) + ": face ",
      "line " + std::to_string(f_line) + ": face ",
      "line " + std::to_string(f_line) + ": face ",
      "line " + std::to_string(f_line) + ": face ",
      "file ends inside face ",
  };
  const std::vector<std::string> serial =
      serial_errors_everywhere(static_cast<Parser>(&io_detail::parse_off), kOffPath, broken);
  for (std::size_t b = 0; b < broken.size(); ++b) {
    EXPECT_NE(serial[b].find(where[b]), std::string::npos) << serial[b];
  }
}

// Differential: random edits anywhere in the files (bytes replaced, erased, inserted; the file
// cut) must give the serial reader's mesh or its error, with 3 threads on 97-byte runs.

/// The mesh, or the IoError's message.
struct Outcome {
  std::optional<Mesh> mesh;
  std::string error;
};

Outcome outcome(Parser parse, std::string_view text, int threads, std::size_t run_bytes) {
  try {
    return {parse("edited", text, threads, run_bytes), {}};
  } catch (const IoError& e) {
    return {std::nullopt, e.what()};
  }
}

void expect_same_outcomes(Parser parse, const std::string& seed, std::uint32_t rng_seed) {
  std::mt19937 rng(rng_seed);
  const char alphabet[] = "0123456789 -+./#\n\r\txef\x01";
  int errors = 0;
  for (int iteration = 0; iteration < 150; ++iteration) {
    std::string text = seed;
    const int edits = 1 + static_cast<int>(rng() % 3);
    for (int e = 0; e < edits && !text.empty(); ++e) {
      const std::size_t at = rng() % text.size();
      const char byte = alphabet[rng() % (sizeof alphabet - 1)];
      switch (rng() % 4) {
        case 0:
          text[at] = byte;
          break;
        case 1:
          text.erase(at, 1 + rng() % 8);
          break;
        case 2:
          text.insert(at, 1, byte);
          break;
        default:
          if (rng() % 4 == 0) text.resize(at);  // rarely: most cuts end inside a face anyway
      }
    }
    const Outcome serial = outcome(parse, text, 1, io_detail::kTextChunkBytes);
    const Outcome parallel = outcome(parse, text, 3, 97);
    SCOPED_TRACE("iteration " + std::to_string(iteration));
    ASSERT_EQ(parallel.error, serial.error);
    ASSERT_EQ(parallel.mesh.has_value(), serial.mesh.has_value());
    if (serial.mesh) expect_same_mesh(*parallel.mesh, *serial.mesh);
    errors += !serial.error.empty();
  }
  // Both kinds of outcome were met, so both paths were compared.
  EXPECT_GT(errors, 10);
  EXPECT_LT(errors, 140);
}

TEST(ObjParallelRead, RandomlyEditedFilesGiveTheSerialMeshOrError) {
  expect_same_outcomes(static_cast<Parser>(&io_detail::parse_obj), obj_text(), 2024);
}

TEST(OffParallelRead, RandomlyEditedFilesGiveTheSerialMeshOrError) {
  expect_same_outcomes(static_cast<Parser>(&io_detail::parse_off), off_text(true), 2025);
}

// ASCII PLY: the header is read serially, the body's lines in runs.

const std::filesystem::path kPlyPath = "grid.ply";

/// An ascii PLY of the grid: an element before the vertices, vertex lists and normals, faces with
/// a flag after the list, triangle strips, an element after them; blank lines, CRLF and tabs.
std::string ply_text() {
  std::string vertices, faces;
  int face_count = 0;
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      const int i = r * kCols + c;
      const double x = 0.1 * c + 1e-7 * i, y = -0.03 * r / 7.0, z = 1.0 / (1.0 + i);
      if (i % 5 == 0) vertices += '\t';
      vertices += number(x);
      vertices += i % 3 ? " " : " \t ";
      vertices += number(y);
      vertices += ' ';
      vertices += number(z);
      vertices += i % 4 ? " 0 " : " 2 7 8 ";  // a list property between position and normal
      vertices += number(z);
      vertices += ' ';
      vertices += number(-x);
      vertices += ' ';
      vertices += number(y);
      vertices += i % 7 == 0 ? "\r\n" : "\n";
      if (i % 97 == 0) vertices += "\n  \n";
    }
  }
  const auto v = [](int r, int c) { return std::to_string(r * kCols + c); };
  for (int r = 0; r + 1 < kRows; ++r) {
    for (int c = 0; c + 1 < kCols; ++c) {
      if (c % 10 == 3 && c + 2 < kCols) {
        faces += "6 " + v(r, c) + " " + v(r, c + 1) + " " + v(r, c + 2) + " " + v(r + 1, c + 2) +
                 " " + v(r + 1, c + 1) + " " + v(r + 1, c) + " 1\n";
        ++c;
      } else {
        faces += "4\t" + v(r, c) + " " + v(r, c + 1) + " " + v(r + 1, c + 1) + " " + v(r + 1, c) +
                 (c % 5 == 0 ? " 0\r\n" : " 0\n");
      }
      ++face_count;
    }
    if (r % 13 == 0) faces += "\n";
  }
  return "ply\nformat ascii 1.0\ncomment made by text_readers_test\nelement material 2\n"
         "property float shine\nelement vertex " +
         std::to_string(kRows * kCols) +
         "\nproperty double x\nproperty double y\nproperty double z\n"
         "property list uchar int extra\nproperty float nx\nproperty float ny\nproperty float nz\n"
         "element face " +
         std::to_string(face_count) +
         "\nproperty list uchar int vertex_indices\nproperty uchar flag\n"
         "element tristrips 2\nproperty list int int vertex_indices\n"
         "element edge 2\nproperty int v1\nproperty int v2\nend_header\n0.5\n0.25\n" +
         vertices + faces + "5 0 1 60 61 -1\n4 2 3 62 63\n0 1\n1 2\n";
}

TEST(PlyParallelRead, EveryThreadCountAndRunSizeGivesTheSerialMeshBitForBit) {
  const std::string text = ply_text();
  const Mesh serial = serial_read(static_cast<Parser>(&io_detail::parse_ply), kPlyPath, text);
  ASSERT_EQ(serial.V.rows(), kRows * kCols);
  // Per row of cells: 6 hexagons (4 triangles each) and 47 quads (2 each); then the two strips,
  // 0 1 60 61 (ended by a -1) and 2 3 62 63, of two triangles each.
  EXPECT_EQ(serial.F.rows(), (kRows - 1) * (6 * 4 + 47 * 2) + 2 + 2);
  EXPECT_EQ(serial.V(1, 0), 0.1 + 1e-7);
  EXPECT_EQ(serial.N.rows(), serial.V.rows());
  expect_serial_mesh_everywhere(static_cast<Parser>(&io_detail::parse_ply),
                                &io_detail::parse_ply_in_chunks, kPlyPath, text, serial);
}

TEST(PlyParallelRead, ErrorsInTheMiddleOfARunAreTheSerialReadersWordForWord) {
  const std::string text = ply_text();
  const std::size_t v_line = line_in_the_middle(text.substr(0, text.find("\n4\t")), "0.");
  // The faces are the last fifth of the file.
  const std::size_t f_line = line_in_the_middle(text, "4\t", text.size() / 10 * 9);
  const std::string cut = text.substr(0, line_start(text, f_line));
  const std::vector<std::string> broken = {
      with_line(text, v_line, "1.0 2.0x 3.0 0 0 0 1"),
      with_line(text, v_line, "1.0 2.0 3.0 0 0 0"),
      with_line(text, v_line, "1.0 2.0 3.0 2 7 0 0 1"),
      with_line(text, f_line, "2 1 2 0"),
      with_line(text, f_line, "4 1 2 3 99999 0"),
      with_line(text, f_line, "4 1 2 3 4"),
      cut,
  };
  const std::vector<std::string> serial =
      serial_errors_everywhere(static_cast<Parser>(&io_detail::parse_ply), kPlyPath, broken);
  for (std::size_t b = 0; b < broken.size(); ++b) {
    const std::size_t line = b < 3 ? v_line : f_line;
    EXPECT_NE(
        serial[b].find(b < 6 ? "line " + std::to_string(line) + ": " : "file ends inside face"),
        std::string::npos)
        << serial[b];
  }
}

TEST(PlyParallelRead, RandomlyEditedFilesGiveTheSerialMeshOrError) {
  // Edits in the header give header errors, which both reads report before reading any run.
  expect_same_outcomes(static_cast<Parser>(&io_detail::parse_ply), ply_text(), 2026);
}

// ASCII STL: runs cut where a facet opens, each read as a file of its own and renumbered.

const std::filesystem::path kStlPath = "grid.stl";

/// The facet through `corners` (each corner a grid vertex r * kCols + c), keyword case and
/// layout varied by `form`.
void append_facet(std::string& out, const std::vector<int>& corners, int form) {
  const bool upper = form % 7 == 0;
  out += form % 5 == 0 ? "\tfacet normal 0 0 1\r\n"
                       : (upper ? "FACET NORMAL 0 0 1\n" : "facet normal 0 0 1\n");
  out += upper ? "  OUTER LOOP\n" : "  outer loop\n";
  for (const int v : corners) {
    const double x = 0.1 * (v % kCols) + 1e-7, y = 0.1 * (v / kCols), z = 0.01 * (v % 13);
    out += (upper ? "    VERTEX " : "    vertex ") + number(x) + " " + number(y) + "\t" +
           number(z) + "\n";
  }
  out += upper ? "  ENDLOOP\nENDFACET\n" : "  endloop\nendfacet\n";
  if (form % 11 == 0) out += "# a comment line\n\n";
}

/// Two solids over the grid's cells: triangles, quads (two triangles each) and upper-case
/// keywords, CRLF, tabs, comments and blank lines between facets.
std::string stl_text() {
  std::string out = "solid grid\n";
  for (int r = 0; r + 1 < kRows; ++r) {
    if (r == kRows / 2) out += "endsolid grid\nsolid second half\n";
    for (int c = 0; c + 1 < kCols; ++c) {
      const int a = r * kCols + c, b = a + 1, d = a + kCols + 1, e = a + kCols;
      if (c % 4 == 1) {
        append_facet(out, {a, b, d, e}, r + c);
      } else {
        append_facet(out, {a, b, d}, r + c);
        append_facet(out, {a, d, e}, r + c + 1);
      }
    }
  }
  return out + "endsolid second half\n";
}

TEST(StlParallelRead, EveryThreadCountAndRunSizeGivesTheSerialMeshBitForBit) {
  const std::string text = stl_text();
  const Mesh serial = serial_read(static_cast<Parser>(&io_detail::parse_stl), kStlPath, text);
  // Per row of cells: 15 quads (cells c = 1, 5, ...) and 44 pairs of triangles.
  const int facets_per_row = 15 + 2 * 44;
  ASSERT_EQ(serial.F.rows(), (kRows - 1) * (15 * 2 + 44 * 2));
  EXPECT_EQ(serial.face_source.maxCoeff(), (kRows - 1) * facets_per_row - 1);
  EXPECT_EQ(serial.V.rows(), (kRows - 1) * (15 * 4 + 44 * 6));
  expect_serial_mesh_everywhere(static_cast<Parser>(&io_detail::parse_stl),
                                &io_detail::parse_stl_in_chunks, kStlPath, text, serial);
}

TEST(StlParallelRead, ErrorsInTheMiddleOfARunAreTheSerialReadersWordForWord) {
  const std::string text = stl_text();
  const std::size_t v_line = line_in_the_middle(text, "    vertex ");
  const std::size_t f_line = line_in_the_middle(text, "facet normal");
  const std::vector<std::string> broken{
      with_line(text, v_line, "    vertex 1 2"),
      with_line(text, v_line, "    vertex 1 2x 3"),
      with_line(text, v_line, "    vertx 1 2 3"),
      with_line(text, f_line, "  outer loop"),   // a facet without its `facet` line
      with_line(text, f_line, "endsolid grid"),  // a solid closed inside another's facets
      with_line(text, v_line, "endfacet"),       // a facet cut before its loop ends
      text.substr(0, line_start(text, f_line)),  // the file ends inside a solid
  };
  const std::vector<std::string> serial =
      serial_errors_everywhere(static_cast<Parser>(&io_detail::parse_stl), kStlPath, broken);
  for (std::size_t b = 0; b < broken.size(); ++b) EXPECT_NE(serial[b], "no error") << b;
}

TEST(StlParallelRead, RandomlyEditedFilesGiveTheSerialMeshOrError) {
  expect_same_outcomes(static_cast<Parser>(&io_detail::parse_stl), stl_text(), 2027);
}

// The exact weld: the first corner of each position, on any number of threads, by hashes first
// (then checked) or by positions throughout.

TEST(StlWeld, FirstEqualCornersAreTheSameOnEveryThreadCountAndEitherWay) {
  std::mt19937 rng(7);
  RowMatrixX3d V(200000, 3);  // 200,000 corners over about 20,000 positions, -0 and NaN among them
  std::vector<std::array<double, 3>> positions(20000);
  for (auto& p : positions) {
    for (double& x : p) x = static_cast<double>(rng() % 1000) / 7.0 - 50.0;
  }
  positions[3] = {0.0, 0.0, 0.0};
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const auto& p = positions[rng() % positions.size()];
    V.row(i) << p[0], p[1], p[2];
    if (p[0] == 0.0 && p[1] == 0.0 && p[2] == 0.0 && i % 2 == 1) V(i, 1) = -0.0;
    if (i % 997 == 0) V(i, 2) = std::numeric_limits<double>::quiet_NaN();
  }
  // The serial definition: the first earlier corner with the same coordinates (-0 == 0, NaN
  // equal to nothing).
  std::vector<std::int32_t> expected(static_cast<std::size_t>(V.rows()));
  std::map<std::array<double, 3>, std::int32_t> first_of;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    expected[i] = static_cast<std::int32_t>(i);
    if (!V.row(i).allFinite()) continue;
    const std::array<double, 3> key{V(i, 0) + 0.0, V(i, 1) + 0.0, V(i, 2) + 0.0};
    expected[i] = first_of.emplace(key, static_cast<std::int32_t>(i)).first->second;
  }
  EXPECT_GT(first_of.size(), 15000u);
  for (const int threads : kThreads) {
    for (const bool hashes_first : {true, false}) {
      SCOPED_TRACE("threads " + std::to_string(threads) + (hashes_first ? ", hashes" : ""));
      EXPECT_EQ(io_detail::first_equal_corners(V, threads, hashes_first), expected);
    }
  }
  // The weld itself: vertices in first-corner order on every thread count.
  Mesh one;
  one.V = V;
  one.F.resize(V.rows() / 3, 3);
  for (Eigen::Index f = 0; f < one.F.rows(); ++f) one.F.row(f) << 3 * f, 3 * f + 1, 3 * f + 2;
  Mesh many = one;
  io_detail::weld_corners(one, 0.0, true, 1);
  io_detail::weld_corners(many, 0.0, true, 3);
  EXPECT_TRUE(same_bits(one.V, many.V));
  EXPECT_TRUE(same_bits(one.F, many.F));
  EXPECT_TRUE(same_bits(one.corner_vertex, many.corner_vertex));
  EXPECT_EQ(one.V.rows(), static_cast<Eigen::Index>(first_of.size()) + 201);  // + NaN corners
}

}  // namespace
}  // namespace focal

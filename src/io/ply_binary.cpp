// The binary body of a PLY file, little or big endian: fixed-size vertex and triangle records in
// parallel blocks, anything else record by record.

#include <algorithm>
#include <bit>
#include <limits>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/core/execution.h"
#include "io/file_bytes.h"
#include "io/ply.h"
#include "io/ply_read.h"
#include "io/text_scan.h"

namespace focal::io_detail::ply {

class BinaryBody {
 public:
  BinaryBody(const std::filesystem::path& path, std::string_view data, std::size_t offset,
             bool swap, int threads)
      : path_(path),
        begin_(reinterpret_cast<const unsigned char*>(data.data())),
        p_(begin_ + offset),
        end_(begin_ + data.size()),
        swap_(swap),
        threads_(threads) {}

  /// Bytes not read yet (after read_body: those after the last element).
  [[nodiscard]] std::size_t remaining() const { return static_cast<std::size_t>(end_ - p_); }

  /// Rejects a count that cannot fit in the rest of the file, before anything is allocated.
  void check_fits(const PlyElement& e) const {
    const std::size_t min_bytes = e.min_binary_bytes();
    const auto remaining = static_cast<std::uint64_t>(end_ - p_);
    if (min_bytes > 0 && e.count > remaining / min_bytes && e.fixed_size()) {
      // Fixed-size elements: say exactly which one the file ends in.
      const std::uint64_t complete = remaining / min_bytes;
      fail_at_offset(path_, offset() + complete * min_bytes,
                     "file ends inside " + e.name + " " + std::to_string(complete) + " of " +
                         std::to_string(e.count));
    }
    // Binary: every element has its bytes (no separator that the last one may lack).
    io_detail::check_records_fit(path_, "byte offset " + std::to_string(offset()), e.count,
                                 min_bytes, remaining, e.name + " elements");
  }

  void read_vertices(const PlyElement& e, const std::vector<int>& roles, double* V, double* N) {
    if (e.fixed_size()) {
      read_fixed_vertices(e, roles, V, N);
      return;
    }
    for (std::uint64_t i = 0; i < e.count; ++i) {
      const unsigned char* start = p_;
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const auto& prop = e.properties[k];
        if (prop.is_list) {
          skip_list(prop, e, i, start);
          continue;
        }
        require(scalar_size(prop.type), e, i, start);
        const int role = roles[k];
        if (role >= 0) {
          const double value = load_as<double>(p_, prop.type, swap_);
          if (role < 3) {
            V[3 * i + role] = value;
          } else {
            N[3 * i + role - 3] = value;
          }
        }
        p_ += scalar_size(prop.type);
      }
    }
  }

  /// Reads the face element straight into mesh.F and mesh.face_source, in parallel, when every
  /// face is a triangle stored at a fixed stride (no other list property) and every index is in
  /// range. Returns false, having read and changed nothing, otherwise: read_faces() then gives
  /// the exact results and error messages of the serial reader.
  bool read_triangle_faces(const PlyElement& e, std::size_t list_prop, std::int64_t vertex_count,
                           Mesh& mesh) {
    std::size_t count_offset = 0;
    std::size_t stride = 0;
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const auto& prop = e.properties[k];
      if (k == list_prop) {
        count_offset = stride;
        stride += scalar_size(prop.count_type) + 3 * scalar_size(prop.type);
      } else if (prop.is_list) {
        return false;
      } else {
        stride += scalar_size(prop.type);
      }
    }
    const auto remaining = static_cast<std::uint64_t>(end_ - p_);
    if (e.count == 0 || e.count > remaining / stride ||
        e.count > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) {
      return false;
    }
    const PlyProperty& list = e.properties[list_prop];
    const std::size_t count_bytes = scalar_size(list.count_type);
    const std::size_t item = scalar_size(list.type);
    // `list uchar int` (or uint) in the host's byte order, as focal and most writers store it.
    const bool common = !swap_ && list.count_type == Scalar::uint8 &&
                        (list.type == Scalar::int32 || list.type == Scalar::uint32);
    const auto faces = static_cast<std::int64_t>(e.count);
    RowMatrixX3i F(faces, 3);
    Eigen::VectorXi source(faces);
    detail::advise_huge_pages(F.data(), sizeof(std::int32_t) * F.size());
    detail::advise_huge_pages(source.data(), sizeof(std::int32_t) * source.size());
    std::int32_t* corners = F.data();
    const unsigned char* first = p_ + count_offset;
    // One flag per block of faces (blocks independent of the thread count): the first pass
    // both checks and converts, so a valid file is read once.
    constexpr std::int64_t kBlock = 1 << 14;
    std::vector<unsigned char> bad(static_cast<std::size_t>((faces + kBlock - 1) / kBlock), 0);
    detail::parallel_for_blocks(faces, kBlock, threads_, [&](std::int64_t begin, std::int64_t end) {
      bool ok = true;
      if (common) {
        for (std::int64_t f = begin; f < end; ++f) {
          const unsigned char* rec = first + static_cast<std::size_t>(f) * stride;
          ok &= rec[0] == 3;
          for (int c = 0; c < 3; ++c) {
            const std::int64_t v = list.type == Scalar::int32
                                       ? std::int64_t{load<std::int32_t>(rec + 1 + 4 * c, false)}
                                       : std::int64_t{load<std::uint32_t>(rec + 1 + 4 * c, false)};
            ok &= v >= 0 && v < vertex_count;
            corners[3 * f + c] = static_cast<std::int32_t>(v);
          }
          source[f] = static_cast<std::int32_t>(f);
        }
      } else {
        for (std::int64_t f = begin; f < end; ++f) {
          const unsigned char* rec = first + static_cast<std::size_t>(f) * stride;
          ok &= load_as<std::int64_t>(rec, list.count_type, swap_) == 3;
          rec += count_bytes;
          for (int c = 0; c < 3; ++c) {
            const std::int64_t v = load_as<std::int64_t>(rec + c * item, list.type, swap_);
            ok &= v >= 0 && v < vertex_count;
            corners[3 * f + c] = static_cast<std::int32_t>(v);
          }
          source[f] = static_cast<std::int32_t>(f);
        }
      }
      if (!ok) bad[static_cast<std::size_t>(begin / kBlock)] = 1;
    });
    if (std::find(bad.begin(), bad.end(), 1) != bad.end()) return false;
    mesh.F = std::move(F);
    mesh.face_source = std::move(source);
    p_ += e.count * stride;
    return true;
  }

  void read_faces(const PlyElement& e, std::size_t list_prop, std::int64_t vertex_count,
                  FaceLists kind, io_detail::TriangleCollector& triangles) {
    std::vector<std::int32_t> corners;
    for (std::uint64_t f = 0; f < e.count; ++f) {
      const unsigned char* start = p_;
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const auto& prop = e.properties[k];
        if (k != list_prop) {
          if (prop.is_list) {
            skip_list(prop, e, f, start);
          } else {
            require(scalar_size(prop.type), e, f, start);
            p_ += scalar_size(prop.type);
          }
          continue;
        }
        const std::int64_t n = read_count(prop, e, f, start);
        check_list_length(path_, "byte offset " + std::to_string(offset_of(start)), n, f, kind);
        const std::size_t item = scalar_size(prop.type);
        require(static_cast<std::size_t>(n) * item, e, f, start);
        corners.resize(static_cast<std::size_t>(n));
        for (std::int64_t c = 0; c < n; ++c) {
          const std::int64_t v = load_as<std::int64_t>(p_, prop.type, swap_);
          if (!valid_corner(v, vertex_count, kind)) {
            fail_at_offset(path_, offset_of(start),
                           bad_corner(e, f, v, vertex_count) +
                               byte_order_hint(p_, prop.type, vertex_count, kind));
          }
          corners[static_cast<std::size_t>(c)] = static_cast<std::int32_t>(v);
          p_ += item;
        }
        add_face_list(corners, f, kind, triangles);
      }
    }
  }

  void skip_element(const PlyElement& e) {
    if (e.fixed_size()) {
      p_ += e.count * e.min_binary_bytes();  // check_fits() made sure this is inside the file
      return;
    }
    for (std::uint64_t i = 0; i < e.count; ++i) {
      const unsigned char* start = p_;
      for (const auto& prop : e.properties) {
        if (prop.is_list) {
          skip_list(prop, e, i, start);
        } else {
          require(scalar_size(prop.type), e, i, start);
          p_ += scalar_size(prop.type);
        }
      }
    }
  }

  [[nodiscard]] std::uint64_t offset() const { return offset_of(p_); }

 private:
  /// Fixed-size records: check_fits() made sure all of them are in the file, so no record can
  /// fail and they are converted in parallel blocks.
  void read_fixed_vertices(const PlyElement& e, const std::vector<int>& roles, double* V,
                           double* N) {
    if (e.count == 0) return;  // V and N may be null: no column pointers to form
    struct Field {
      std::size_t offset;
      Scalar type;
      double* out;  ///< column base: out[3 * i]
    };
    Field fields[6];
    int used = 0;
    std::size_t offset = 0;
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const int role = roles[k];
      if (role >= 0) {
        fields[used++] = {offset, e.properties[k].type, role < 3 ? V + role : N + role - 3};
      }
      offset += scalar_size(e.properties[k].type);
    }
    const std::size_t stride = offset;
    const unsigned char* first = p_;
    detail::parallel_for_blocks(
        static_cast<std::int64_t>(e.count), std::int64_t{1} << 14, threads_,
        [&](std::int64_t begin, std::int64_t end) {
          // Field by field, so that the type switch is decided once per block and field.
          for (int k = 0; k < used; ++k) {
            const Field& field = fields[k];
            const unsigned char* rec = first + field.offset;
            switch (field.type) {
              case Scalar::float64:
                for (std::int64_t i = begin; i < end; ++i) {
                  field.out[3 * i] =
                      load<double>(rec + static_cast<std::size_t>(i) * stride, swap_);
                }
                break;
              case Scalar::float32:
                for (std::int64_t i = begin; i < end; ++i) {
                  field.out[3 * i] = load<float>(rec + static_cast<std::size_t>(i) * stride, swap_);
                }
                break;
              default:
                for (std::int64_t i = begin; i < end; ++i) {
                  field.out[3 * i] = load_as<double>(rec + static_cast<std::size_t>(i) * stride,
                                                     field.type, swap_);
                }
                break;
            }
          }
        });
    p_ += e.count * stride;
  }

  /// " (wrong byte order ...?)" when the index at p, out of range, would be in range read in the
  /// other byte order; else "".
  [[nodiscard]] std::string byte_order_hint(const unsigned char* p, Scalar t,
                                            std::int64_t vertex_count, FaceLists kind) const {
    if (scalar_size(t) == 1 ||
        !valid_corner(load_as<std::int64_t>(p, t, !swap_), vertex_count, kind)) {
      return "";
    }
    return " (wrong byte order? the header says binary_" +
           std::string(swap_ == (std::endian::native == std::endian::little) ? "big" : "little") +
           "_endian)";
  }

  [[nodiscard]] std::uint64_t offset_of(const unsigned char* p) const {
    return static_cast<std::uint64_t>(p - begin_);
  }

  /// Throws unless `bytes` more bytes of element `index` (which began at `start`) are present.
  void require(std::size_t bytes, const PlyElement& e, std::uint64_t index,
               const unsigned char* start) const {
    if (static_cast<std::size_t>(end_ - p_) < bytes) {
      fail_at_offset(path_, offset_of(start),
                     "file ends inside " + e.name + " " + std::to_string(index) + " of " +
                         std::to_string(e.count));
    }
  }

  std::int64_t read_count(const PlyProperty& prop, const PlyElement& e, std::uint64_t index,
                          const unsigned char* start) {
    require(scalar_size(prop.count_type), e, index, start);
    const std::int64_t n = load_as<std::int64_t>(p_, prop.count_type, swap_);
    p_ += scalar_size(prop.count_type);
    if (n < 0) {
      fail_at_offset(
          path_, offset_of(start),
          e.name + " " + std::to_string(index) + ": negative list length " + std::to_string(n));
    }
    // Each item takes a byte at least: a longer list cannot be in the file (and n * item size
    // could overflow for 64-bit counts).
    if (static_cast<std::uint64_t>(n) > static_cast<std::uint64_t>(end_ - p_)) {
      require(static_cast<std::size_t>(end_ - p_) + 1, e, index, start);
    }
    return n;
  }

  void skip_list(const PlyProperty& prop, const PlyElement& e, std::uint64_t index,
                 const unsigned char* start) {
    const std::int64_t n = read_count(prop, e, index, start);
    const std::size_t bytes = static_cast<std::size_t>(n) * scalar_size(prop.type);
    require(bytes, e, index, start);
    p_ += bytes;
  }

  const std::filesystem::path& path_;
  const unsigned char* begin_;
  const unsigned char* p_;
  const unsigned char* end_;
  bool swap_;
  int threads_;  ///< of the parallel passes over fixed-size records
};

Mesh read_binary_body(const std::filesystem::path& path, std::string_view data,
                      const PlyHeader& header, const BodyPlan& plan, int threads) {
  const bool file_big = header.encoding == PlyEncoding::binary_big_endian;
  const bool host_big = std::endian::native == std::endian::big;
  BinaryBody body(path, data, header.body_offset, file_big != host_big, threads);
  Mesh mesh = read_body(path, header, plan, body);
  // Bytes after the last element: not part of the mesh (a line end some writers add, or a wrong
  // count); read as before, but said, since they may be elements the header does not count.
  if (const std::size_t extra = body.remaining(); extra > 1) {
    if (const auto& warn = current_execution().warning) {
      warn(path.string() + ": " + std::to_string(extra) +
           " bytes follow the last element the header declares; ignored");
    }
  }
  return mesh;
}

}  // namespace focal::io_detail::ply

#pragma once
// Packed arrays: lamina's compressed form of its binned tables (docs/formats.md, "Packed arrays").
// A table of f over a hemisphere grid is smooth along φ in every model and noisy only in the low
// bits of the reference, so each array of float16 or float32 values is
//   1. seen as [outer, n, channels] (its last axis the channels, the one before it the axis the
//      values vary smoothly along: φ bins, or the incident-plane slice's x),
//   2. reordered to [outer, channels, n] and replaced by its differences along n (the first value
//      kept), taken on the IEEE bit patterns as unsigned integers modulo 2^16 or 2^32 (exact,
//      and for positive floats the bit pattern grows like log f, so a smooth f gives small steps),
//   3. split into byte planes (every element's low byte, then every next byte, ...),
//   4. compressed with zlib's deflate (RFC 1950: a zlib stream, what Python's zlib.decompress,
//      the browser's DecompressionStream("deflate") and zlib's uncompress read), in chunks of
//      1 MiB deflated side by side over the threads and joined into that one stream (the bytes do
//      not depend on the thread count).
// Lossless: unpacking gives back the exact bits. On the quick study the tables shrink to about an
// eighth of their float16 size (docs/performance.md).
//
// The file (configs/<id>/tables.lza, reference_se.lza, the reference cache) is one text line
// "lamina-array 1", one line of JSON {"dtype": "float16"|"float32", "shape": [...], ...}, then
// the packed bytes.

#include "core/npy.h"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace lamina {

/// zlib's level for step 4: 3 keeps most of level 6's ratio (the quick study's packed tables are
/// about 6 % larger) in under half its time, which the study's outputs and the explorer page
/// spend most of theirs on (docs/performance.md).
inline constexpr int kPackDeflateLevel = 3;

/// Packs `count` elements of `width` bytes (2 or 4) laid out as [count / (n·channels), n,
/// channels] (steps 1–4 above). `channels` ≥ 1, `n` ≥ 1, count a multiple of n·channels.
std::string pack_elements(const void* elements, std::size_t count, std::size_t width, std::size_t n,
                          std::size_t channels);
/// The inverse: `count` elements of `width` bytes into `out` (which holds count·width bytes).
/// Throws InputError naming `where` when the bytes are not a packed array of that size.
void unpack_elements(std::string_view packed, void* out, std::size_t count, std::size_t width,
                     std::size_t n, std::size_t channels, const std::string& where);

/// The bytes of a packed-array file of `data` (C order, `shape` with at least 2 axes, the last
/// one the channels, the one before it the smooth axis), stored as float16 (`half`, the
/// conversion of npy_float16: clamped to ±65504, NaN kept) or float32. `axes` names the axes
/// (written into the header for readers, may be empty).
std::string packed_array_file(const std::vector<float>& data, const std::vector<std::size_t>& shape,
                              bool half, const std::vector<std::string>& axes = {});

/// Reads a packed-array file (as NpyFloat32: shape, data as float, whether it held float16).
/// InputError naming the file and the field for anything else.
NpyFloat32 read_packed_array(const std::filesystem::path& path);
/// The same from the file's bytes (`where` names it in errors).
NpyFloat32 parse_packed_array(std::string_view bytes, const std::string& where);

/// A study's table `stem` in `dir`: `stem`.lza, or, from a study written before packed arrays,
/// `stem`.npy. InputError naming the .lza file when neither is there.
NpyFloat32 read_study_array(const std::filesystem::path& dir, const std::string& stem);
/// The file read_study_array reads: `stem`.lza, or `stem`.npy when only it is there.
std::filesystem::path study_array_path(const std::filesystem::path& dir, const std::string& stem);
/// Whether `dir` holds `stem`.lza or `stem`.npy.
bool has_study_array(const std::filesystem::path& dir, const std::string& stem);

}  // namespace lamina

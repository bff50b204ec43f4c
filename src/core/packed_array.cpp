#include "core/packed_array.h"

#include "core/atomic_file.h"
#include "core/check.h"
#include "core/error.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <zlib.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>
#include <numeric>
#include <sstream>

namespace lamina {

static_assert(std::endian::native == std::endian::little, "packed arrays assume little-endian");

namespace {

constexpr std::string_view kMagic = "lamina-array 1\n";

// Scratch memory kept by each thread between calls: the byte planes of one table are megabytes,
// and a fresh zero-filled buffer per table cost more (the fill and the page faults of a new
// mapping) than deflating it. A buffer only grows while it is used, and one past kKeptBytes is
// given back when its use ends, so a large table does not stay held.
template <class T>
class Scratch {
  public:
    explicit Scratch(std::vector<T>& buffer) : buffer_(buffer) {}
    Scratch(const Scratch&) = delete;
    Scratch& operator=(const Scratch&) = delete;
    ~Scratch() {
        if (buffer_.size() * sizeof(T) > kKeptBytes) std::vector<T>().swap(buffer_);
    }
    /// `count` elements, their values unspecified.
    T* get(std::size_t count) {
        if (buffer_.size() < count) buffer_.resize(count);
        return buffer_.data();
    }

  private:
    static constexpr std::size_t kKeptBytes = std::size_t(64) << 20;
    std::vector<T>& buffer_;
};

// Steps 1–3 on unsigned integers of one width: [outer, n, channels] → [outer, channels, n],
// differences along n (modulo 2^bits), byte planes (`planes`: count · sizeof(U) bytes).
template <class U>
void transform(const U* v, std::size_t count, std::size_t n, std::size_t channels,
               unsigned char* planes) {
    const std::size_t row = n * channels, outer = count / row;
    std::vector<U> run(n);  // one channel's run along n, as differences
    for (std::size_t o = 0; o < outer; ++o)
        for (std::size_t c = 0; c < channels; ++c) {
            const U* src = v + o * row + c;
            U previous = 0;
            for (std::size_t k = 0; k < n; ++k) {
                const U x = src[k * channels];
                run[k] = U(x - previous);
                previous = x;
            }
            const std::size_t at = o * row + c * n;
            for (std::size_t b = 0; b < sizeof(U); ++b) {
                unsigned char* plane = planes + b * count + at;
                for (std::size_t k = 0; k < n; ++k)
                    plane[k] = static_cast<unsigned char>((run[k] >> (8 * b)) & 0xff);
            }
        }
}

// The inverse of transform: the byte planes back into v, [outer, n, channels].
template <class U>
void untransform(const unsigned char* planes, U* v, std::size_t count, std::size_t n,
                 std::size_t channels) {
    const std::size_t row = n * channels, outer = count / row;
    std::vector<U> run(n);  // one channel's run along n, as differences
    for (std::size_t o = 0; o < outer; ++o)
        for (std::size_t c = 0; c < channels; ++c) {
            const std::size_t at = o * row + c * n;
            for (std::size_t k = 0; k < n; ++k)
                run[k] = U(planes[at + k]);
            for (std::size_t b = 1; b < sizeof(U); ++b) {
                const unsigned char* plane = planes + b * count + at;
                for (std::size_t k = 0; k < n; ++k)
                    run[k] = U(run[k] | U(U(plane[k]) << (8 * b)));
            }
            U* dst = v + o * row + c;
            U x = 0;
            for (std::size_t k = 0; k < n; ++k) {
                x = U(x + run[k]);
                dst[k * channels] = x;
            }
        }
}

// Deflate (zlib format, RFC 1950) in fixed chunks of the input, compressed side by side over the
// threads and concatenated, as pigz does: each chunk is a raw deflate stream primed with the 32 KiB
// before it (so matches reach back across chunk edges as they would in one stream) and ended by a
// sync flush (an empty stored block that realigns to a byte), the last by the final block; the
// zlib header and the Adler-32 of the whole input go around them. The chunks do not depend on the
// thread count, so neither do the bytes; at level 3 they are as large as one stream's (within
// 0.1 % on the quick study's tables).
std::string deflate_chunked(const unsigned char* data, std::size_t size) {
    constexpr std::size_t kChunk = std::size_t(1) << 20, kWindow = std::size_t(1) << 15;
    const std::size_t n = std::max<std::size_t>(1, (size + kChunk - 1) / kChunk);
    std::vector<std::string> parts(n);
    std::vector<int> failed(n, 0);
#pragma omp parallel for schedule(dynamic, 1) if (n > 1)
    for (long i = 0; i < long(n); ++i) {
        const std::size_t begin = std::size_t(i) * kChunk, end = std::min(size, begin + kChunk);
        const bool last = std::size_t(i) + 1 == n;
        z_stream z{};
        if (deflateInit2(&z, kPackDeflateLevel, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
            failed[std::size_t(i)] = 1;
            continue;
        }
        const std::size_t dictionary = std::min(kWindow, begin);
        if (dictionary > 0 &&
            deflateSetDictionary(&z, data + begin - dictionary, uInt(dictionary)) != Z_OK)
            failed[std::size_t(i)] = 1;
        std::string& out = parts[std::size_t(i)];
        out.resize(deflateBound(&z, uLong(end - begin)) + 16);  // + the sync flush's marker
        z.next_in = const_cast<Bytef*>(data + begin);
        z.avail_in = uInt(end - begin);
        z.next_out = reinterpret_cast<Bytef*>(out.data());
        z.avail_out = uInt(out.size());
        const int rc = deflate(&z, last ? Z_FINISH : Z_SYNC_FLUSH);
        // A sync flush that filled the buffer may have output left: room must remain.
        if (rc != (last ? Z_STREAM_END : Z_OK) || z.avail_in != 0 || z.avail_out == 0)
            failed[std::size_t(i)] = 1;
        out.resize(out.size() - z.avail_out);
        deflateEnd(&z);
    }
    LAMINA_CHECK(std::find(failed.begin(), failed.end(), 1) == failed.end());
    // RFC 1950 header: deflate, 32 KiB window, FLEVEL 1 ("fast", zlib's levels 2–5), check bits.
    static_assert(kPackDeflateLevel >= 2 && kPackDeflateLevel <= 5);
    std::string stream = {char(0x78), char(0x5e)};
    for (const std::string& part : parts)
        stream += part;
    const uLong adler = adler32_z(adler32(0, nullptr, 0), data, size);
    for (int shift = 24; shift >= 0; shift -= 8)
        stream += char((adler >> shift) & 0xff);
    return stream;
}

}  // namespace

std::string pack_elements(const void* elements, std::size_t count, std::size_t width, std::size_t n,
                          std::size_t channels) {
    LAMINA_CHECK((width == 2 || width == 4) && n >= 1 && channels >= 1 &&
                 count % (n * channels) == 0);
    thread_local std::vector<unsigned char> planes_buffer;
    Scratch planes_scratch(planes_buffer);
    const std::size_t bytes = count * width;
    unsigned char* planes = planes_scratch.get(bytes);
    if (width == 2)
        transform(static_cast<const std::uint16_t*>(elements), count, n, channels, planes);
    else
        transform(static_cast<const std::uint32_t*>(elements), count, n, channels, planes);
    return deflate_chunked(planes, bytes);
}

void unpack_elements(std::string_view packed, void* out, std::size_t count, std::size_t width,
                     std::size_t n, std::size_t channels, const std::string& where) {
    if (!((width == 2 || width == 4) && n >= 1 && channels >= 1 && count % (n * channels) == 0))
        throw InputError(where, "shape", "not a packed array's layout");
    thread_local std::vector<unsigned char> planes_buffer;
    Scratch planes_scratch(planes_buffer);
    const std::size_t bytes = count * width;
    unsigned char* planes = planes_scratch.get(bytes);
    uLongf size = uLongf(bytes);
    const int rc = uncompress(planes, &size, reinterpret_cast<const Bytef*>(packed.data()),
                              uLong(packed.size()));
    if (rc != Z_OK || size != bytes)
        throw InputError(where, "data",
                         rc == Z_BUF_ERROR || (rc == Z_OK && size != bytes)
                             ? fmt::format("the packed data does not hold the {} values of the "
                                           "header's shape",
                                           count)
                             : fmt::format("not a zlib stream (zlib: {})", zError(rc)));
    if (width == 2)
        untransform(planes, static_cast<std::uint16_t*>(out), count, n, channels);
    else
        untransform(planes, static_cast<std::uint32_t*>(out), count, n, channels);
}

std::string packed_array_file(const std::vector<float>& data, const std::vector<std::size_t>& shape,
                              bool half, const std::vector<std::string>& axes) {
    LAMINA_CHECK(shape.size() >= 2 && element_count(shape) == data.size());
    nlohmann::json header;
    header["dtype"] = half ? "float16" : "float32";
    header["shape"] = shape;
    if (!axes.empty()) header["axes"] = axes;
    header["packing"] =
        "channels before the second-last axis, differences along it, byte planes, "
        "deflate (docs/formats.md)";
    const std::size_t n = shape[shape.size() - 2], channels = shape.back();
    std::string packed;
    if (half) {
        thread_local std::vector<std::uint16_t> bits_buffer;
        Scratch scratch(bits_buffer);
        std::uint16_t* bits = scratch.get(data.size());
        for (std::size_t i = 0; i < data.size(); ++i)
            bits[i] = float_to_half(data[i]);
        packed = pack_elements(bits, data.size(), 2, n, channels);
    } else {
        packed = pack_elements(data.data(), data.size(), 4, n, channels);
    }
    return std::string(kMagic) + header.dump() + "\n" + packed;
}

NpyFloat32 parse_packed_array(std::string_view bytes, const std::string& where) {
    if (bytes.substr(0, kMagic.size()) != kMagic)
        throw InputError(where, "", "not a lamina packed array (no 'lamina-array 1' line)");
    const std::size_t eol = bytes.find('\n', kMagic.size());
    if (eol == std::string_view::npos) throw InputError(where, "header", "truncated");
    NpyFloat32 a;
    try {
        const nlohmann::json h =
            nlohmann::json::parse(bytes.substr(kMagic.size(), eol - kMagic.size()));
        const std::string dtype = h.at("dtype").get<std::string>();
        if (dtype != "float16" && dtype != "float32")
            throw InputError(where, "dtype",
                             fmt::format("'{}': expected float16 or float32", dtype));
        a.half = dtype == "float16";
        a.shape = h.at("shape").get<std::vector<std::size_t>>();
    } catch (const nlohmann::json::exception& e) {
        throw InputError(where, "header", fmt::format("malformed: {}", e.what()));
    }
    if (a.shape.size() < 2)
        throw InputError(where, "shape", "expected at least 2 axes (…, n, channels)");
    std::size_t count = 1;
    for (std::size_t d : a.shape) {
        if (d == 0 || count > (std::size_t(1) << 34) / d)
            throw InputError(where, "shape",
                             fmt::format("[{}]: each axis in [1, ...], at most 2^34 values",
                                         fmt::join(a.shape, ", ")));
        count *= d;
    }
    const std::size_t n = a.shape[a.shape.size() - 2], channels = a.shape.back();
    const std::string_view packed = bytes.substr(eol + 1);
    a.data.resize(count);
    if (a.half) {
        thread_local std::vector<std::uint16_t> bits_buffer;
        Scratch scratch(bits_buffer);
        std::uint16_t* bits = scratch.get(count);
        unpack_elements(packed, bits, count, 2, n, channels, where);
        for (std::size_t i = 0; i < count; ++i)
            a.data[i] = half_to_float(bits[i]);
    } else {
        unpack_elements(packed, a.data.data(), count, 4, n, channels, where);
    }
    return a;
}

NpyFloat32 read_packed_array(const std::filesystem::path& path) {
    // Bounded as every table lamina reads: a device or a runaway file is refused, not read on.
    return parse_packed_array(
        read_regular_file_bounded(path, kMaxTableFileBytes, "the packed array"), path.string());
}

std::filesystem::path study_array_path(const std::filesystem::path& dir, const std::string& stem) {
    const std::filesystem::path packed = dir / (stem + ".lza"), npy = dir / (stem + ".npy");
    return !std::filesystem::exists(packed) && std::filesystem::exists(npy) ? npy : packed;
}

NpyFloat32 read_study_array(const std::filesystem::path& dir, const std::string& stem) {
    const std::filesystem::path path = study_array_path(dir, stem);
    return path.extension() == ".npy" ? read_npy_float32(path) : read_packed_array(path);
}

bool has_study_array(const std::filesystem::path& dir, const std::string& stem) {
    return std::filesystem::exists(dir / (stem + ".lza")) ||
           std::filesystem::exists(dir / (stem + ".npy"));
}

}  // namespace lamina

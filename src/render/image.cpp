#include "render/image.h"

#include "core/error.h"

#include <fmt/format.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

namespace lamina {

std::uint8_t tone_map_channel(double linear, double exposure_ev) {
    const double x = std::max(0.0, linear) * std::exp2(exposure_ev);
    // Narkowicz 2015: (x(2.51x + 0.03)) / (x(2.43x + 0.59) + 0.14), clamped to [0, 1].
    const double y = std::clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
    const double s = y <= 0.0031308 ? 12.92 * y : 1.055 * std::pow(y, 1 / 2.4) - 0.055;
    return std::uint8_t(std::lround(std::clamp(s, 0.0, 1.0) * 255));
}

namespace {
std::uint8_t encode_srgb(double y) {
    y = std::clamp(y, 0.0, 1.0);
    const double s = y <= 0.0031308 ? 12.92 * y : 1.055 * std::pow(y, 1 / 2.4) - 0.055;
    return std::uint8_t(std::lround(s * 255));
}
}  // namespace

void write_png(const std::filesystem::path& path, const Image& image, double exposure_ev,
               bool tone_map) {
    std::FILE* fp = std::fopen(path.c_str(), "wb");
    if (!fp) throw InputError(path.string(), "", "cannot open for writing");
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!png || !info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        std::fclose(fp);
        throw InputError(path.string(), "", "libpng failed to write the image");
    }
    png_init_io(png, fp);
    png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8,
                 PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    std::vector<std::uint8_t> row(std::size_t(image.width) * 3);
    for (int y = 0; y < image.height; ++y) {
        for (int x = 0; x < image.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const double v = image.at(x, y)[c];
                row[std::size_t(x) * 3 + c] =
                    tone_map ? tone_map_channel(v, exposure_ev) : encode_srgb(v);
            }
        png_write_row(png, row.data());
    }
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    if (std::fclose(fp) != 0) throw InputError(path.string(), "", "cannot finish writing");
}

// ---- EXR (OpenEXR file layout, "Technical introduction to OpenEXR" and "OpenEXR file layout") --
// magic 20000630, version 2 (single-part scanline), header attributes (name, type, size, value),
// an empty name ends the header, then one 64-bit offset per scanline block and the blocks:
// y (int), byte count (int), then each channel's row in alphabetical order (B, G, R).
namespace {
struct Writer {
    std::string bytes;
    template <typename T>
    void put(T v) {
        char b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));  // little-endian hosts (x86-64, arm64), as EXR requires
        bytes.append(b, sizeof(T));
    }
    void str(const std::string& s) { bytes.append(s.c_str(), s.size() + 1); }
    void attribute(const std::string& name, const std::string& type, const std::string& value) {
        str(name);
        str(type);
        put<std::int32_t>(std::int32_t(value.size()));
        bytes += value;
    }
};
}  // namespace

void write_exr(const std::filesystem::path& path, const Image& image) {
    Writer h;
    h.put<std::int32_t>(20000630);
    h.put<std::int32_t>(2);
    {
        Writer ch;
        for (const char* name : {"B", "G", "R"}) {
            ch.str(name);
            ch.put<std::int32_t>(2);  // FLOAT
            ch.put<std::uint8_t>(0);  // pLinear
            ch.put<std::uint8_t>(0);
            ch.put<std::uint8_t>(0);
            ch.put<std::uint8_t>(0);
            ch.put<std::int32_t>(1);
            ch.put<std::int32_t>(1);
        }
        ch.put<std::uint8_t>(0);
        h.attribute("channels", "chlist", ch.bytes);
    }
    h.attribute("compression", "compression", std::string(1, '\0'));
    Writer box;
    for (int v : {0, 0, image.width - 1, image.height - 1})
        box.put<std::int32_t>(v);
    h.attribute("dataWindow", "box2i", box.bytes);
    h.attribute("displayWindow", "box2i", box.bytes);
    h.attribute("lineOrder", "lineOrder", std::string(1, '\0'));
    Writer f1;
    f1.put<float>(1.f);
    h.attribute("pixelAspectRatio", "float", f1.bytes);
    Writer v2;
    v2.put<float>(0.f);
    v2.put<float>(0.f);
    h.attribute("screenWindowCenter", "v2f", v2.bytes);
    h.attribute("screenWindowWidth", "float", f1.bytes);
    h.put<std::uint8_t>(0);
    const std::uint64_t row_bytes = std::uint64_t(image.width) * 3 * 4;
    const std::uint64_t first = h.bytes.size() + 8 * std::uint64_t(image.height);
    for (int y = 0; y < image.height; ++y)
        h.put<std::uint64_t>(first + std::uint64_t(y) * (8 + row_bytes));
    for (int y = 0; y < image.height; ++y) {
        h.put<std::int32_t>(y);
        h.put<std::int32_t>(std::int32_t(row_bytes));
        for (int c : {2, 1, 0})
            for (int x = 0; x < image.width; ++x)
                h.put<float>(image.at(x, y)[c]);
    }
    std::ofstream out(path, std::ios::binary);
    out.write(h.bytes.data(), std::streamsize(h.bytes.size()));
    if (!out) throw InputError(path.string(), "", "cannot write the EXR file");
}

Image read_exr(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    const std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::size_t p = 8;
    auto cstr = [&] {
        const std::string s(b.c_str() + p);
        p += s.size() + 1;
        return s;
    };
    auto get_i32 = [&](std::size_t at) {
        std::int32_t v;
        std::memcpy(&v, b.data() + at, 4);
        return v;
    };
    int w = 0, h = 0;
    while (true) {
        const std::string name = cstr();
        if (name.empty()) break;
        cstr();
        const std::int32_t size = get_i32(p);
        p += 4;
        if (name == "dataWindow") {
            w = get_i32(p + 8) + 1;
            h = get_i32(p + 12) + 1;
        }
        p += std::size_t(size);
    }
    Image img(w, h);
    p += 8 * std::size_t(h);
    for (int y = 0; y < h; ++y) {
        const int row = get_i32(p);
        p += 8;
        for (int c : {2, 1, 0})
            for (int x = 0; x < w; ++x) {
                float v;
                std::memcpy(&v, b.data() + p, 4);
                p += 4;
                img.at(x, row)[c] = v;
            }
    }
    return img;
}

}  // namespace lamina

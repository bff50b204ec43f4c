#include "render/image.h"

#include "core/error.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
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
    // Above 10⁶ the fit is past white (its limit is 2.51 / 2.43 > 1); the cap keeps x² finite.
    // NaN (not ≥ 0) maps to black.
    const double x = linear >= 0 ? std::min(linear * std::exp2(exposure_ev), 1e6) : 0.0;
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
// EXR through OpenEXR (Debian's libopenexr-dev): 32-bit float R, G, B scanlines, ZIP compression,
// written to a temporary file and renamed into place.
void write_exr(const std::filesystem::path& path, const Image& image) {
    const std::filesystem::path tmp = path.string() + ".tmp-exr";
    try {
        Imf::Header header(image.width, image.height);
        header.compression() = Imf::ZIP_COMPRESSION;
        for (const char* c : {"R", "G", "B"})
            header.channels().insert(c, Imf::Channel(Imf::FLOAT));
        Imf::OutputFile file(tmp.c_str(), header);
        Imf::FrameBuffer fb;
        char* base = reinterpret_cast<char*>(const_cast<Rgbf*>(image.pixels.data()));
        const std::size_t xs = sizeof(Rgbf), ys = sizeof(Rgbf) * std::size_t(image.width);
        fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
        fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
        fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
        file.setFrameBuffer(fb);
        file.writePixels(image.height);
    } catch (const std::exception& e) {
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw InputError(path.string(), "", fmt::format("cannot write the EXR file: {}", e.what()));
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) throw InputError(path.string(), "", "cannot move the EXR file into place");
}

Image read_exr(const std::filesystem::path& path) {
    try {
        Imf::InputFile file(path.c_str());
        const Imath::Box2i dw = file.header().dataWindow();
        Image image(dw.max.x - dw.min.x + 1, dw.max.y - dw.min.y + 1);
        Imf::FrameBuffer fb;
        char* base = reinterpret_cast<char*>(image.pixels.data()) -
                     (std::ptrdiff_t(dw.min.x) + std::ptrdiff_t(dw.min.y) * image.width) *
                         std::ptrdiff_t(sizeof(Rgbf));
        const std::size_t xs = sizeof(Rgbf), ys = sizeof(Rgbf) * std::size_t(image.width);
        fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
        fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xs, ys));
        fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xs, ys));
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);
        return image;
    } catch (const std::exception& e) {
        throw InputError(path.string(), "", fmt::format("cannot read the EXR file: {}", e.what()));
    }
}

}  // namespace lamina

// SPDX-License-Identifier: MIT
#include "viewer/exr_writer.h"

#include <unistd.h>

#include <stdexcept>
#include <string>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include "viewer/eye_picture.h"
#include "viewer/pending_output.h"
#include "viewer/picture_writer.h"

namespace bounce {

void write_exr(const std::filesystem::path& path, int width, int height, const std::vector<Rgb>& pixels) {
    if (width <= 0 || height <= 0 || pixels.size() != std::size_t(width) * std::size_t(height))
        throw std::runtime_error(path.string() + ": cannot write the OpenEXR picture (size and pixels differ)");
    // Interleaved float RGB, the layout OpenEXR's frame buffer reads with a stride.
    std::vector<float> rgb(3 * pixels.size());
    for (std::size_t i = 0; i < pixels.size(); ++i)
        for (std::size_t k = 0; k < 3; ++k) rgb[3 * i + k] = float(pixels[i][int(k)]);
    std::filesystem::path tmp = path;
    tmp += ".tmp-" + std::to_string(::getpid()) + ".exr";
    const PendingOutput pending(tmp.c_str());
    bool ok = false;
    try {
        Imf::Header header(width, height);
        header.compression() = Imf::ZIP_COMPRESSION;
        Imf::FrameBuffer frame;
        const std::size_t x_stride = 3 * sizeof(float), y_stride = x_stride * std::size_t(width);
        const char* names[3] = {"R", "G", "B"};
        for (std::size_t k = 0; k < 3; ++k) {
            header.channels().insert(names[k], Imf::Channel(Imf::FLOAT));
            frame.insert(names[k], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(rgb.data() + k), x_stride, y_stride));
        }
        Imf::OutputFile file(tmp.c_str(), header);
        file.setFrameBuffer(frame);
        file.writePixels(height);
        ok = true;
    } catch (const std::exception&) {
        ok = false;  // commit_output removes the temporary and names the file
    }
    commit_output(tmp, path, ok, "OpenEXR picture");
}

bool is_linear_picture(const std::filesystem::path& path) {
    const std::string ext = picture_extension(path);
    return ext == ".pfm" || ext == ".exr";
}

void write_linear_picture(const std::filesystem::path& path, int width, int height, const std::vector<Rgb>& pixels) {
    if (picture_extension(path) == ".exr") return write_exr(path, width, height, pixels);
    write_pfm(path, width, height, pixels);
}

}  // namespace bounce

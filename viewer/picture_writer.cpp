// SPDX-License-Identifier: MIT
#include "viewer/picture_writer.h"

#include <unistd.h>

#include <cctype>

#include <vtkImageData.h>
#include <vtkImageWriter.h>
#include <vtkJPEGWriter.h>
#include <vtkPNGWriter.h>
#include <vtkSmartPointer.h>

#include "viewer/pending_output.h"

namespace bounce {

std::string picture_extension(const std::filesystem::path& picture) {
    std::string ext = picture.extension().string();
    for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

void write_picture(vtkImageData* image, const std::filesystem::path& picture) {
    const std::string ext = picture_extension(picture);
    const bool jpeg = ext != ".png";
    std::filesystem::path tmp = picture;
    tmp += ".tmp-" + std::to_string(::getpid()) + ext;
    const PendingOutput pending(tmp.c_str());
    vtkSmartPointer<vtkImageWriter> writer;
    if (jpeg) {
        auto j = vtkSmartPointer<vtkJPEGWriter>::New();
        j->SetQuality(95);
        writer = j;
    } else {
        writer = vtkSmartPointer<vtkPNGWriter>::New();
    }
    writer->SetFileName(tmp.string().c_str());
    writer->SetInputData(image);
    writer->Write();
    commit_output(tmp, picture, writer->GetErrorCode() == 0 && std::filesystem::exists(tmp), jpeg ? "JPEG" : "PNG");
}

}  // namespace bounce

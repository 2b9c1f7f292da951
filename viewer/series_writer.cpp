// SPDX-License-Identifier: MIT
#include "viewer/series_writer.h"

#include "viewer/pending_output.h"

#include <cstdio>
#include <stdexcept>

namespace bounce {

SeriesWriter::SeriesWriter(std::filesystem::path pvd, const PatchMesh& mesh, ExportInfo info)
    : m_pvd(std::move(pvd)), m_mesh(mesh), m_info(std::move(info)) {
    m_folder = m_pvd.parent_path() / (m_pvd.stem().string() + "_series");
    std::filesystem::create_directories(m_folder);
}

void SeriesWriter::add(const SolveResult& so_far) {
    char name[64];
    std::snprintf(name, sizeof name, "step_%09zu.vtu", so_far.steps);
    write_vtu(m_folder / name, m_mesh, so_far, m_info);
    m_entries.emplace_back(so_far.steps, (m_folder.filename() / name).string());
}

void SeriesWriter::finish(const SolveResult& final) {
    // The last snapshot may have been taken at the final step while still "running": the
    // final solution replaces it, so the series ends in the file the solve wrote.
    if (!m_entries.empty() && m_entries.back().first == final.steps) m_entries.pop_back();
    {
        char name[64];
        std::snprintf(name, sizeof name, "step_%09zu.vtu", final.steps);
        write_vtu(m_folder / name, m_mesh, final, m_info);
        m_entries.emplace_back(final.steps, (m_folder.filename() / name).string());
    }
    write_text_file(
        m_pvd,
        [&](std::ostream& out) {
            out << "<?xml version=\"1.0\"?>\n"
                   "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n";
            for (const auto& [step, file] : m_entries)
                out << "    <DataSet timestep=\"" << step << "\" group=\"\" part=\"0\" file=\"" << file << "\"/>\n";
            out << "  </Collection>\n</VTKFile>\n";
        },
        ".pvd file");
}

}  // namespace bounce

// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "mesh/meshing/patch_mesh.h"
#include "solver/linear/solve_result.h"
#include "viewer/vtu_writer.h"

namespace bounce {

/// A ParaView time series of a solve: one .vtu per snapshot in a folder beside the .pvd, and
/// the .pvd collection (step number as time) written, temporary file then rename, by finish().
/// ParaView's time slider then replays the convergence.
class SeriesWriter {
public:
    /// pvd: the collection file (e.g. cornell.pvd); snapshots go to <stem>_series/.
    SeriesWriter(std::filesystem::path pvd, const PatchMesh& mesh, ExportInfo info);
    /// One snapshot: the state so far, written with its own powers, seconds and status.
    void add(const SolveResult& so_far);
    /// Adds the final solution and writes the .pvd.
    void finish(const SolveResult& final);
    const std::filesystem::path& pvd() const { return m_pvd; }

private:
    std::filesystem::path m_pvd, m_folder;
    const PatchMesh& m_mesh;
    ExportInfo m_info;
    std::vector<std::pair<std::size_t, std::string>> m_entries;  // step, file relative to the pvd
};

}  // namespace bounce

// SPDX-License-Identifier: MIT
#include "solver/form_factors/surface_form_factor.h"

namespace bounce {

double surface_form_factor(const std::vector<Patch>& patches, const FormFactorEstimator& estimator, int from, int to) {
    std::vector<float> row(patches.size());
    double num = 0.0, area = 0.0;
    for (std::size_t i = 0; i < patches.size(); ++i) {
        if (patches[i].surface != from) continue;
        area += patches[i].area;
        estimator.compute_row(i, row);
        for (std::size_t j = 0; j < patches.size(); ++j)
            if (patches[j].surface == to) num += patches[i].area * double(row[j]);
    }
    return area > 0 ? num / area : 0.0;
}

}  // namespace bounce

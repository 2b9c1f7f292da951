// SPDX-License-Identifier: MIT
#include "app/convergence_log.h"

#include <ostream>
#include <sstream>

#include "viewer/pending_output.h"

namespace bounce::app {

void write_log_csv(const std::filesystem::path& path, const std::vector<SolveResult>& runs,
                   const std::vector<std::string>& form_factors, const std::vector<double>& ff_seconds) {
    write_text_file(
        path,
        [&](std::ostream& out) {
            out << "form_factors,solver,step,seconds,form_factor_seconds,residual,unshot_fraction,rms_error,max_error,"
                   "ambient_rms_error\n";
            out.precision(10);
            auto opt = [&](double v) {
                if (v < 0) return std::string();
                std::ostringstream t;
                t.precision(10);
                t << v;
                return t.str();
            };
            for (std::size_t k = 0; k < runs.size(); ++k)
                for (const auto& r : runs[k].log)
                    out << form_factors[k] << ',' << runs[k].solver << ',' << r.step << ',' << r.seconds << ','
                        << ff_seconds[k] << ',' << opt(r.residual) << ',' << opt(r.unshot_fraction) << ','
                        << opt(r.rms_error) << ',' << opt(r.max_error) << ',' << opt(r.ambient_rms_error) << '\n';
        },
        "convergence log");
}

}  // namespace bounce::app

// SPDX-License-Identifier: MIT
#pragma once

namespace bounce {

/// Debian's VTK renders only through X. When DISPLAY is unset, this starts a private Xvfb
/// (its display number chosen by Xvfb itself, -displayfd) and points DISPLAY at it for the
/// lifetime of the object; with DISPLAY set it does nothing. Throws std::runtime_error when
/// no display can be had (Xvfb missing).
class VirtualDisplay {
public:
    VirtualDisplay();
    ~VirtualDisplay();
    VirtualDisplay(const VirtualDisplay&) = delete;
    VirtualDisplay& operator=(const VirtualDisplay&) = delete;

private:
    int m_pid = -1;
};

}  // namespace bounce

// SPDX-License-Identifier: MIT
#include "viewer/virtual_display.h"

#include <sys/wait.h>
#include <unistd.h>
#include <csignal>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include <fcntl.h>

namespace bounce {

VirtualDisplay::VirtualDisplay() {
    const char* d = std::getenv("DISPLAY");
    if (d && *d) return;
    int fds[2];
    if (::pipe(fds) != 0) throw std::runtime_error("cannot start Xvfb: pipe failed");
    const pid_t pid = ::fork();
    if (pid < 0) throw std::runtime_error("cannot start Xvfb: fork failed");
    if (pid == 0) {
        ::close(fds[0]);
        const int devnull = ::open("/dev/null", O_RDWR);
        if (devnull >= 0) {
            ::dup2(devnull, STDIN_FILENO);
            ::dup2(devnull, STDOUT_FILENO);
            ::dup2(devnull, STDERR_FILENO);
        }
        const std::string fd = std::to_string(fds[1]);
        ::execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1920x1080x24", "-nolisten", "tcp",
                 static_cast<char*>(nullptr));
        ::_exit(127);
    }
    ::close(fds[1]);
    m_pid = pid;
    std::string number;
    char c;
    while (::read(fds[0], &c, 1) == 1 && c != '\n') number += c;
    ::close(fds[0]);
    if (number.empty()) {
        ::kill(m_pid, SIGTERM);
        ::waitpid(m_pid, nullptr, 0);
        m_pid = -1;
        throw std::runtime_error("no display: DISPLAY is unset and Xvfb could not be started (apt-get install xvfb)");
    }
    ::setenv("DISPLAY", (":" + number).c_str(), 1);
}

VirtualDisplay::~VirtualDisplay() {
    if (m_pid > 0) {
        ::kill(m_pid, SIGTERM);
        ::waitpid(m_pid, nullptr, 0);
        ::unsetenv("DISPLAY");
    }
}

}  // namespace bounce

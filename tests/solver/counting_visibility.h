// SPDX-License-Identifier: MIT
// A visibility backend that counts the segments it is asked about, for tests that assert
// which work is skipped (no rays in an empty room, none over a shaft-tested link).
#pragma once

#include <atomic>
#include <memory>
#include <span>
#include <string>

#include "solver/visibility/visibility.h"

namespace bounce {

/// Counts the segments traced through an inner backend.
class CountingVisibility final : public Visibility {
public:
    explicit CountingVisibility(std::unique_ptr<Visibility> inner) : m_inner(std::move(inner)) {
        m_offset = m_inner->offset();  // the same lifted rays as the inner backend's callers
    }
    bool occluded(const glm::dvec3& a, const glm::dvec3& b) const override {
        ++segments;
        return m_inner->occluded(a, b);
    }
    void occluded(std::span<const Segment> s, std::span<std::uint8_t> blocked) const override {
        segments += s.size();
        m_inner->occluded(s, blocked);
    }
    int first_patch(const glm::dvec3& a, const glm::dvec3& b) const override {
        ++segments;
        return m_inner->first_patch(a, b);
    }
    std::string name() const override { return "counting " + m_inner->name(); }
    mutable std::atomic<std::size_t> segments{0};

private:
    std::unique_ptr<Visibility> m_inner;
};

}  // namespace bounce

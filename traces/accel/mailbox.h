#pragma once
// Mailboxes (docs/accel.md, "Mailboxes"): in a structure whose cells or leaves list primitive
// references (a grid, a kd-tree, an octree), a primitive that overlaps several cells is listed in
// each, and a ray crossing them tests it again in each. A mailbox remembers what the ray has
// tested so the retest (and its 48-byte triangle fetch) is skipped. The classic mailbox keeps a
// ray id per primitive in the scene (Amanatides & Woo 1987; Arnaldi, Priol & Bouatouch 1987), a
// write to the scene per test that hardware with many rays in flight cannot afford; here, as in
// hashed or per-ray mailboxing, each ray context holds a small table of the primitives it tested
// last: `entries` of them, first in first out, compared all at once (a tiny CAM beside the ray's
// stack, in the model's traversal unit: `mailbox.entries`).
//
// Skipping is exact: every structure tests a triangle against the ray's own [tmin, tmax] and
// keeps the closest hit by (t, prim) (traces/isect/leaf_kernel.h), so a second test of the same
// triangle cannot change the hit, the cull distance, or whether an any-hit ray stops. The one
// exception is a MASK triangle whose alpha test rejected the hit: a retest while it would still be
// the closest runs the alpha test again, so such a triangle is not recorded (its retest happens
// exactly as without a mailbox). Hence with a mailbox every work count but the triangle tests is
// unchanged, and triangle tests + mailbox hits = the triangle tests without one.
#include <algorithm>
#include <cstdint>

namespace rtsim {

class Mailbox {
public:
    static constexpr uint32_t kMaxEntries = 64;

    /// 0 turns the mailbox off.
    void set_entries(uint32_t entries) {
        m_entries = std::min(entries, kMaxEntries);
        clear();
    }
    uint32_t entries() const { return m_entries; }
    bool enabled() const { return m_entries != 0; }
    /// A new ray: the table is emptied.
    void clear() { m_size = m_next = 0; }
    bool contains(uint32_t prim) const {
        for (uint32_t i = 0; i < m_size; ++i)
            if (m_slot[i] == prim) return true;
        return false;
    }
    /// Records a tested primitive, replacing the oldest when full.
    void insert(uint32_t prim) {
        m_slot[m_next] = prim;
        m_next = m_next + 1 == m_entries ? 0 : m_next + 1;
        m_size = std::min(m_size + 1, m_entries);
    }

private:
    uint32_t m_entries = 0, m_size = 0, m_next = 0;
    uint32_t m_slot[kMaxEntries];
};

}  // namespace rtsim

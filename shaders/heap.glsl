// The per-invocation cut heap of shared/lightcuts.h. Slots below K live in
// workgroup shared memory; slots K and above spill to a global buffer laid
// out for the whole tile. K, the capacity and the spill layout are
// specialization constants chosen by the host from the device's shared
// memory size, the workgroup size and the capacity, which is
// LightTree::cut_heap_capacity(max_cut): the tree's interior nodes, never
// more than the cut, so a huge max_cut over a small tree costs nothing.
//
// The global buffer has room for all kHeapCapacity slots of every
// invocation: slots below K are where the shared part is saved while a
// refinement waits for its next dispatch.
#ifndef LC_HEAP_GLSL
#define LC_HEAP_GLSL

layout(constant_id = kSpecHeapShared) const uint kHeapShared = 1u;
layout(constant_id = kSpecHeapCapacity) const uint kHeapCapacity = 2u;
layout(constant_id = kSpecSpillStride) const uint kSpillStride = 1u;

layout(std430, binding = kBindingHeapSpill) buffer HeapSpill { CutEntry heap_spill[]; };

// Slot-major, so neighbouring invocations touch neighbouring entries.
shared CutEntry s_heap[kHeapShared * gl_WorkGroupSize.x];

bool g_heap_spilled = false;   // this sample's heap went past kHeapShared slots
bool g_heap_overflow = false;  // ... or past its capacity (a bug: nothing stored)

uint lc_shared_slot(uint slot) { return slot * gl_WorkGroupSize.x + gl_LocalInvocationIndex; }
uint lc_global_slot(uint slot) { return slot * kSpillStride + gl_GlobalInvocationID.x; }

CutEntry lc_heap_load(uint slot) {
    if (slot < kHeapShared) return s_heap[lc_shared_slot(slot)];
    if (slot < kHeapCapacity) return heap_spill[lc_global_slot(slot)];
    return CutEntry(0u, 0.0f, 0.0f, 0.0f, 0.0f);
}

void lc_heap_store(uint slot, CutEntry e) {
    if (slot < kHeapShared) {
        s_heap[lc_shared_slot(slot)] = e;
    } else if (slot < kHeapCapacity) {
        g_heap_spilled = true;
        heap_spill[lc_global_slot(slot)] = e;
    } else {
        g_heap_overflow = true;
    }
}

// Shared slots to global memory and back, around a pause between dispatches.
void lc_heap_save(uint heap_size) {
    for (uint slot = 0u; slot < min(heap_size, kHeapShared); ++slot)
        heap_spill[lc_global_slot(slot)] = s_heap[lc_shared_slot(slot)];
}

void lc_heap_restore(uint heap_size) {
    for (uint slot = 0u; slot < min(heap_size, kHeapShared); ++slot)
        s_heap[lc_shared_slot(slot)] = heap_spill[lc_global_slot(slot)];
}

#define LC_HEAP_LOAD(i) lc_heap_load(i)
#define LC_HEAP_STORE(i, e) lc_heap_store(i, e)

#endif

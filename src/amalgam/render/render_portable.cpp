// The portable copy of the hot paths (the x86-64 baseline, SSE2; util/isa.h).
#include "amalgam/render/render_isa.inl"

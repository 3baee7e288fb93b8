// Lets the kernel headers in this folder compile as C++ as well as GLSL.
// C++: include inside a struct body after `using namespace glm;` at namespace
// scope, so the kernel functions become member functions that see the
// struct's buffer pointers through the LC_* accessor macros.
#ifndef LC_SHARED_GLSL_COMPAT_H
#define LC_SHARED_GLSL_COMPAT_H
#ifdef __cplusplus
// Read-only struct arguments: by reference in C++, where a by-value copy
// of a SurfacePoint (144 bytes) per call showed in the CPU profile.
#define LC_IN(T) const T&
#define LC_OUT(T) T&
#define LC_INOUT(T) T&
#define LC_KCONST static constexpr
// No multiply-add is fused on the CPU (-ffp-contract=off): nothing to mark.
#define LC_PRECISE
#else
#define LC_PRECISE precise
#define LC_KCONST const
#define LC_IN(T) in T
#define LC_OUT(T) out T
#define LC_INOUT(T) inout T
#endif
#endif

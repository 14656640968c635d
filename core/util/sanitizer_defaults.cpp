// sanitizer_defaults.cpp — the defaults of sanitizer builds (SYLVA_SANITIZE) for two
// findings inside OpenImageIO 2.4 and one bug of GCC 12's sanitizer runtime, not in sylva. Linked into every executable of such a
// build (an object library: a static archive would never pull these unreferenced hooks
// in), so every test binary that reads an image gets them, whatever stage it tests.
// GCC says ASan with __SANITIZE_ADDRESS__, clang 14 (the fuzz preset) with __has_feature.
#if defined(__SANITIZE_ADDRESS__)
#define SYLVA_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SYLVA_ASAN 1
#endif
#endif
#if defined(SYLVA_ASAN)
// OpenImageIO 2.4's TextureSystem::destroy deletes its implementation through the base
// class pointer with the base class's size (a sized-delete mismatch inside the library,
// not in sylva: ASan reports it from libOpenImageIO's own frame). Sanitizer builds turn
// that one check off by default; ASAN_OPTIONS still wins.
//
// intercept_tls_get_addr=0: up to GCC 13 the runtime's __tls_get_addr interceptor takes a
// dynamic TLS block whose start lies sizeof(Glibc_2_19_tls_header) past a page boundary
// for a pre-2.25 glibc block and reads the two words before it as an address and a
// length. Since glibc 2.25 no such header exists; a malloc'd block lands there by chance,
// and LeakSanitizer's stop-the-world tracer then dies at exit ("Tracer caught signal 11")
// after every test passed. Mesa's llvmpipe threads allocate dynamic TLS, so the GL tests
// hit it about once per CI run (gl.RenderGl.PineSceneWithReliefAndBarkMatchesTheCpu,
// gl.GlFog.*). Without the interceptor LSan still scans static TLS and every stack.
extern "C" const char* __asan_default_options() {
  return "new_delete_type_mismatch=0:intercept_tls_get_addr=0";
}
// OpenImageIO 2.4 keeps a reader's error message in storage it never frees once a read
// failed (the string assigned in ImageInput::geterror): LeakSanitizer would fail every
// test of a broken image file on that library-internal allocation.
// OIIO keeps each thread's last error string in storage it never frees. With ASan's fast
// unwinder the stack of that string stops in libstdc++ (built without frame pointers) at
// basic_string::_M_assign, above OIIO's geterror, so both spellings are listed: a
// truncated image's read error (image_io.cpp, check_image_opens) leaves the second.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:OpenImageIO_v2_4::ImageInput::geterror\n"
         "leak:std::__cxx11::basic_string<char, std::char_traits<char>, std::allocator<char> >::_M_assign\n";
}
#endif

// sanitizer_defaults.cpp — the defaults of sanitizer builds (SYLVA_SANITIZE) for two
// findings inside OpenImageIO 2.4, not in sylva. Linked into every executable of such a
// build (an object library: a static archive would never pull these unreferenced hooks
// in), so every test binary that reads an image gets them, whatever stage it tests.
#if defined(__SANITIZE_ADDRESS__)
// OpenImageIO 2.4's TextureSystem::destroy deletes its implementation through the base
// class pointer with the base class's size (a sized-delete mismatch inside the library,
// not in sylva: ASan reports it from libOpenImageIO's own frame). Sanitizer builds turn
// that one check off by default; ASAN_OPTIONS still wins.
extern "C" const char* __asan_default_options() { return "new_delete_type_mismatch=0"; }
// OpenImageIO 2.4 keeps a reader's error message in storage it never frees once a read
// failed (the string assigned in ImageInput::geterror): LeakSanitizer would fail every
// test of a broken image file on that library-internal allocation.
extern "C" const char* __lsan_default_suppressions() { return "leak:OpenImageIO_v2_4::ImageInput::geterror\n"; }
#endif

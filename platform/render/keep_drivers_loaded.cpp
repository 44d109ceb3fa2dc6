// Sanitizer builds only (FIRE_SANITIZE), compiled into every executable that links fire_render.
//
// LeakSanitizer treats the globals of mapped libraries as roots. Lavapipe keeps process-lifetime caches in
// its globals, and the Vulkan loader dlcloses the driver at vkDestroyInstance, so those caches become
// "leaks" whose frames belong to no module: nothing a suppression can name. Keeping every library mapped
// (the executable's dlclose interposes the C library's) leaves them reachable, so LeakSanitizer reports
// nothing of the driver's, while anything of ours is still checked as before.
extern "C" int dlclose(void*) { return 0; }

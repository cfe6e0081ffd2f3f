// A shared library that is not a Tilth plugin.
extern "C" __attribute__((visibility("default"))) int some_function() { return 42; }

// libsystemc defines main() and needs an sc_main; the tests run under GoogleTest's main instead,
// so this one is never called.
#include <systemc>

int sc_main(int, char**) { return 0; }

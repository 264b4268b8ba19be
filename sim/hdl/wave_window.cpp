// wave_window_close() for wave_window.v: closes the dump that $dumpvars opened.
//
// Verilator has no Verilog task for this ($dumpoff is ignored); the model's symbol table closes
// its dumper (and flushes the file). The cocotb runner names every model Vtop.
#include "Vtop__Syms.h"
#include "svdpi.h"

extern "C" void wave_window_close() {
    const auto* scope = static_cast<const VerilatedScope*>(svGetScope());
    static_cast<Vtop__Syms*>(scope->symsp())->_traceDumpClose();
}

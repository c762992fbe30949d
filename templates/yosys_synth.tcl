{{ header }}
# FuseSoC/edalize yosys script of the core's `synth` target (technology-independent:
# edalize's own template calls synth_<arch>, which exists only for FPGA families). edalize
# copies this file to the work directory and sources it with its generated procs.
yosys -import
source edalize_yosys_procs.tcl
verilog_defaults -push
verilog_defaults -add -defer
set_defines
set_incdirs
read_files
set_params
verilog_defaults -pop
# edalize defines a Tcl proc `synth`: call the yosys command itself.
yosys synth -top $top
stat
write_json $name.json

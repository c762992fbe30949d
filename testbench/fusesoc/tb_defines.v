// tofprobe: the macros testbench/tb.v expects, for tools that take files, not -D flags
// (FuseSoC's filesets). Listed before tb.v in the same compilation: the vectors are
// copied into the simulator's work directory, so their path prefix is "./".
`define TB_TOP tofprobe_top
`define TB_VECTORS "./"

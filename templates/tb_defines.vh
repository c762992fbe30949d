{{ header }}
// The macros testbench/tb.v expects, for tools that take files, not -D flags (FuseSoC's
// filesets): listed before tb.v in the same compilation. The core copies the vectors into
// the simulator's work directory, so their path prefix is "./".
`define TB_TOP {{ top }}
`define TB_VECTORS "./"

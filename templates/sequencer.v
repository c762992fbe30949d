{{ header }}
// The chip's one sequencer (docs/pixel-contract.md "The reference sequencer" and "Array"):
// after rst, {{ n }} pulse strobes one every {{ c }} cycles{% if fourier %} (each with its probe ROM address, pulse
// index mod {{ l }}){% endif %}, then the readout phase walks PIXELS pixels row-major (COLS a row), one
// readout strobe every SLOT cycles, and ends one cycle after the last slot. The single pixel's
// top is PIXELS = COLS = 1, SLOT = {{ r + 1 }} (the readout strobe, then {{ r + 1 }} idle cycles while
// its words come out); the array's top walks its R x C pixels. With DOUBLE_BUFFER = 1 the
// walk runs beside the next frame's pulses, which wait after the frame's last pulse for
// max(PIXELS*SLOT + 1, {{ n }}*{{ c }} + 1) - {{ n }}*{{ c }} cycles (the `swap` strobe is the walk's first cycle).
// The Rust twin is `tofprobe_pixel::chip::ChipSequencer`; both step the same registers.
module {{ name }} #(
    parameter integer PIXELS = 1,
    parameter integer COLS = 1,
    parameter integer SLOT = {{ r + 1 }},
    parameter integer DOUBLE_BUFFER = 0,
    // The counters' widths: the walk's pixel index (its end value PIXELS included), row,
    // column, slot cycle and hold. The defaults are the single pixel's walk; the array's
    // top sets them (none is derived here: Icarus 11 crashes evaluating $clog2 parameters
    // beside the gate-level cell models).
    parameter integer QW = 1,
    parameter integer RW = 1,
    parameter integer CW = 1,
    parameter integer SW = {{ sw1 }},
    parameter integer HW = 1,
    // Double-buffered: the cycles the pulses wait after a frame's last one beyond the swap
    // cycle, max(PIXELS·SLOT + 1 − N·C − 1, 0) (64 bits: a large array's walk outlasts 2^32
    // cycles).
    parameter [63:0] WAIT = 64'd0
) (
    input  wire clk,
    input  wire rst,
    output wire pulse,
    output wire readout,
    output wire swap,
    output wire [QW - 1:0] q,
    output wire [RW - 1:0] row,
    output wire [CW - 1:0] col{% if fourier %},
    output wire [{{ aw - 1 }}:0] addr{% endif %}
);
    // The counters' end values at their widths (the values fit: the widths are theirs).
    // Constant wires, not localparams ranged by parameters: Icarus 11 crashes on those
    // beside the gate-level cell models.
    /* verilator lint_off WIDTH */
    wire [QW - 1:0] q_end = PIXELS;
    wire [SW - 1:0] sc_end = SLOT - 1;
    wire [CW - 1:0] c_end = COLS - 1;
    wire [HW - 1:0] wt_start = WAIT;
    /* verilator lint_on WIDTH */

    reg ro_phase;
    reg hold;
    reg [{{ pw - 1 }}:0] ph;
    reg [{{ nw - 1 }}:0] pidx;
    reg [QW - 1:0] qi;
    reg [SW - 1:0] sc;
    reg [RW - 1:0] qr;
    reg [CW - 1:0] qc;
    reg [HW - 1:0] wt;
{%- if fourier %}
    reg [{{ aw - 1 }}:0] ai;
    assign addr = ai;
{%- endif %}
    // Single-buffered the pulses wait for the walk; double-buffered for the hold only.
    wire waiting = (DOUBLE_BUFFER != 0) ? hold : ro_phase;
    assign pulse = !rst && !waiting && (ph == {{ pw }}'d0);
    assign readout = !rst && ro_phase && (sc == {SW{1'b0}}) && (qi != q_end);
    assign swap = (DOUBLE_BUFFER != 0) && !rst && ro_phase && (qi == {QW{1'b0}}) && (sc == {SW{1'b0}});
    assign q = qi;
    assign row = qr;
    assign col = qc;
    wire frame_end = !waiting && (ph == {{ pw }}'d{{ c - 1 }}) && (pidx == {{ nw }}'d{{ n - 1 }});

    always @(posedge clk) begin
        if (rst) begin
            ro_phase <= 1'b0;
            hold <= 1'b0;
            ph <= {{ pw }}'d0;
            pidx <= {{ nw }}'d0;
            qi <= {QW{1'b0}};
            sc <= {SW{1'b0}};
            qr <= {RW{1'b0}};
            qc <= {CW{1'b0}};
            wt <= {HW{1'b0}};
{%- if fourier %}
            ai <= {{ aw }}'d0;
{%- endif %}
        end else begin
            // The readout walk: a slot of SLOT cycles per pixel, row-major, then the
            // phase's last cycle.
            if (ro_phase) begin
                if (qi == q_end) begin
                    ro_phase <= 1'b0;
                end else if (sc == sc_end) begin
                    sc <= {SW{1'b0}};
                    qi <= qi + 1'b1;
                    if (qc == c_end) begin
                        qc <= {CW{1'b0}};
                        qr <= qr + 1'b1;
                    end else begin
                        qc <= qc + 1'b1;
                    end
                end else begin
                    sc <= sc + 1'b1;
                end
            end
            // The pulses (double-buffered: the hold after a frame's last pulse).
            if (DOUBLE_BUFFER != 0 && hold) begin
                if (wt == {HW{1'b0}}) hold <= 1'b0;
                else wt <= wt - 1'b1;
            end else if (!waiting) begin
                if (ph == {{ pw }}'d{{ c - 1 }}) begin
                    ph <= {{ pw }}'d0;
                    pidx <= (pidx == {{ nw }}'d{{ n - 1 }}) ? {{ nw }}'d0 : pidx + 1'b1;
{%- if fourier %}
                    ai <= (ai == {{ aw }}'d{{ l - 1 }}) ? {{ aw }}'d0 : ai + 1'b1;
{%- endif %}
                end else begin
                    ph <= ph + 1'b1;
                end
            end
            // The frame's end starts the walk (double-buffered it has finished: the walk
            // is no longer than the frame), after the blocks above so the restart wins.
            if (frame_end) begin
                ro_phase <= 1'b1;
                hold <= (DOUBLE_BUFFER != 0);
                wt <= wt_start;
                qi <= {QW{1'b0}};
                sc <= {SW{1'b0}};
                qr <= {RW{1'b0}};
                qc <= {CW{1'b0}};
{%- if fourier %}
                ai <= {{ aw }}'d0;
{%- endif %}
            end
        end
    end
endmodule

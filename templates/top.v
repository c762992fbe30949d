{{ header }}{% if directed %}
// Top: the pixel{% if fourier %}, the probe ROM{% endif %} and the contract's directed sequencer ("The
// directed sequencer", crates/pixel/src/directed.rs): after rst, the {{ steps.len() }} steps of the
// table below in a loop; a step presents its strobe (pulse and/or readout, or a reset of the
// pixel) at the first of every `every` cycles, `count` times. It drives the refusal paths
// and the reset in the middle of a frame that the reference sequencer never takes. `pulse_o` tells the TDC (and a testbench) that this cycle samples `valid`/`tdc`.{% else %}
// Top: the pixel{% if fourier %}, the probe ROM{% endif %} and the chip's one sequencer (`{{ seq_name }}`, the
// contract's "The reference sequencer" walking one pixel): after rst, {{ n }} pulses one every {{ c }} cycles, then a
// readout cycle and {{ r + 1 }} idle cycles, frame after frame. `pulse_o` tells the TDC
// (and a testbench) that this cycle samples `valid`/`tdc`.{% endif %}
module {{ name }} (
    input  wire clk,
    input  wire rst,
    input  wire valid,
    input  wire [{{ t - 1 }}:0] tdc,
    output wire pulse_o,
    output wire ready,
    output wire rd_valid,
    output wire [{{ ib - 1 }}:0] rd_index,
    output wire [{{ w - 1 }}:0] rd_data
);{% if directed %}
    // The step table: strobe flags, `every` − 1 and `count` − 1 of step `st`.
    reg [{{ stw - 1 }}:0] st;
    reg [{{ ew - 1 }}:0] ph;
    reg [{{ cw - 1 }}:0] cnt;
    reg s_pulse;
    reg s_readout;
    reg s_reset;
    reg [{{ ew - 1 }}:0] s_every;
    reg [{{ cw - 1 }}:0] s_count;
    always @* begin
        case (st)
{%- for s in steps %}
            // {{ s.purpose }}
            {{ stw }}'d{{ s.i }}: begin
                s_pulse = 1'b{{ s.pulse }};
                s_readout = 1'b{{ s.readout }};
                s_reset = 1'b{{ s.reset }};
                s_every = {{ ew }}'d{{ s.every }};
                s_count = {{ cw }}'d{{ s.count }};
            end
{%- endfor %}
            default: begin
                s_pulse = 1'b0;
                s_readout = 1'b0;
                s_reset = 1'b0;
                s_every = {{ ew }}'d0;
                s_count = {{ cw }}'d0;
            end
        endcase
    end
    wire strobe = !rst && (ph == {{ ew }}'d0);
    wire pulse = strobe && s_pulse;
    wire readout = strobe && s_readout;
    // The pixel's reset: the pin, or a reset step's strobe (the sequencer itself runs on).
    wire px_rst /*verilator public_flat_rd*/ = rst || (strobe && s_reset);
    assign pulse_o = pulse;
{%- if fourier %}
    // ROM address: pulse strobes since the last readout strobe, mod {{ l }}.
    reg [{{ aw - 1 }}:0] addr;
    wire [{{ r - 1 }}:0] rom_word;
    {{ rom_name }} u_rom (.addr(addr), .word(rom_word));
{%- endif %}

    always @(posedge clk) begin
        if (rst) begin
            st <= {{ stw }}'d0;
            ph <= {{ ew }}'d0;
            cnt <= {{ cw }}'d0;
{%- if fourier %}
            addr <= {{ aw }}'d0;
{%- endif %}
        end else begin
            if (ph == s_every) begin
                ph <= {{ ew }}'d0;
                if (cnt == s_count) begin
                    cnt <= {{ cw }}'d0;
                    st <= (st == {{ stw }}'d{{ steps.len() - 1 }}) ? {{ stw }}'d0 : st + {{ stw }}'d1;
                end else begin
                    cnt <= cnt + {{ cw }}'d1;
                end
            end else begin
                ph <= ph + {{ ew }}'d1;
            end
{%- if fourier %}
            if (readout || px_rst) begin
                addr <= {{ aw }}'d0;
            end else if (pulse) begin
                addr <= (addr == {{ aw }}'d{{ l - 1 }}) ? {{ aw }}'d0 : addr + {{ aw }}'d1;
            end
{%- endif %}
        end
    end
{% else %}
    // The chip's one sequencer, walking one pixel: its readout slot is the strobe and the
    // {{ r + 1 }} cycles its words take.
    wire pulse;
    wire readout;
    assign pulse_o = pulse;
    /* verilator lint_off UNUSEDSIGNAL */
    wire s_swap;
    wire s_q;
    wire s_row;
    wire s_col;
    /* verilator lint_on UNUSEDSIGNAL */
{%- if fourier %}
    wire [{{ aw - 1 }}:0] addr;
    wire [{{ r - 1 }}:0] rom_word;
    {{ rom_name }} u_rom (.addr(addr), .word(rom_word));
{%- endif %}
    {{ seq_name }} #(
        .PIXELS(1),
        .COLS(1),
        .SLOT({{ r + 1 }}),
        .DOUBLE_BUFFER(0)
    ) u_sequencer (
        .clk(clk),
        .rst(rst),
        .pulse(pulse),
        .readout(readout),
        .swap(s_swap),
        .q(s_q),
        .row(s_row),
        .col(s_col){% if fourier %},
        .addr(addr){% endif %}
    );
{% endif %}
    {{ pixel_name }} u_pixel (
        .clk(clk),
        .rst({% if directed %}px_rst{% else %}rst{% endif %}),
        .pulse(pulse),
        .valid(valid),
        .tdc(tdc),
{%- if fourier %}
        .rom_word(rom_word),
{%- endif %}
        .readout(readout),
        .ready(ready),
        .rd_valid(rd_valid),
        .rd_index(rd_index),
        .rd_data(rd_data)
    );
endmodule

{{ header }}
// Top: the pixel{% if fourier %}, the probe ROM{% endif %} and the pulse/clock sequencer of the
// contract ("The reference sequencer"): after rst, {{ n }} pulses one every {{ c }} cycles, then a
// readout cycle and {{ r + 1 }} idle cycles, frame after frame. `pulse_o` tells the TDC
// (and a testbench) that this cycle samples `valid`/`tdc`.
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
);
    reg ro_phase;
    reg [{{ pw - 1 }}:0] ph;
    reg [{{ nw - 1 }}:0] pidx;
    reg [{{ ib - 1 }}:0] rc;
    wire pulse = !rst && !ro_phase && (ph == {{ pw }}'d0);
    wire readout = !rst && ro_phase && (rc == {{ ib }}'d0);
    assign pulse_o = pulse;
{%- if fourier %}
    reg [{{ aw - 1 }}:0] addr;
    wire [{{ r - 1 }}:0] rom_word;
    {{ rom_name }} u_rom (.addr(addr), .word(rom_word));
{%- endif %}

    always @(posedge clk) begin
        if (rst) begin
            ro_phase <= 1'b0;
            ph <= {{ pw }}'d0;
            pidx <= {{ nw }}'d0;
            rc <= {{ ib }}'d0;
{%- if fourier %}
            addr <= {{ aw }}'d0;
{%- endif %}
        end else if (!ro_phase) begin
            if (ph == {{ pw }}'d{{ c - 1 }}) begin
                ph <= {{ pw }}'d0;
{%- if fourier %}
                addr <= (addr == {{ aw }}'d{{ l - 1 }}) ? {{ aw }}'d0 : addr + {{ aw }}'d1;
{%- endif %}
                if (pidx == {{ nw }}'d{{ n - 1 }}) begin
                    pidx <= {{ nw }}'d0;
                    ro_phase <= 1'b1;
                    rc <= {{ ib }}'d0;
{%- if fourier %}
                    addr <= {{ aw }}'d0;
{%- endif %}
                end else begin
                    pidx <= pidx + {{ nw }}'d1;
                end
            end else begin
                ph <= ph + {{ pw }}'d1;
            end
        end else begin
            if (rc == {{ ib }}'d{{ r + 1 }}) begin
                ro_phase <= 1'b0;
            end else begin
                rc <= rc + {{ ib }}'d1;
            end
        end
    end

    {{ pixel_name }} u_pixel (
        .clk(clk),
        .rst(rst),
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

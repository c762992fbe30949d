{{ header }}
// The superpixel front end (docs/pixel-contract.md "Superpixel"): G × G = {{ n }} SPADs share
// one pixel; each pulse their detections are averaged into the pixel's one (valid, tdc).
// valid = any SPAD valid; tdc = ((s + ⌊n/2⌋) · M[n]) >> {{ k }}, s the sum of the n valid
// SPADs' {{ t }}-bit codes and M[n] = ⌈2^{{ k }} / n⌉ (the reciprocal table below): the mean
// rounded half up, exact for every (s, n). Combinational: no latency, the pixel samples
// (valid, tdc) as it would one SPAD's.
module {{ name }} (
    input  wire [{{ n - 1 }}:0] spad_valid,
    // SPAD i's code in bits [i*{{ t }} +: {{ t }}] (SPADs row-major in the superpixel).
    input  wire [{{ n * t - 1 }}:0] spad_tdc,
    output wire valid,
    output wire [{{ t - 1 }}:0] tdc
);
    // Each SPAD's code (0 when it did not detect) and its count, widened to the sum's.
{%- for (i, c) in codes %}
    wire [{{ sw - 1 }}:0] code_{{ i }} = spad_valid[{{ i }}] ? { {{ sw - t }}'d0, spad_tdc[{{ c * t + t - 1 }}:{{ c * t }}] } : {{ sw }}'d0;
    wire [{{ cw - 1 }}:0] one_{{ i }} = { {{ cw - 1 }}'d0, spad_valid[{{ i }}] };
{%- endfor %}
    wire [{{ sw - 1 }}:0] sum = {{ sum_expr }};
    wire [{{ cw - 1 }}:0] count = {{ count_expr }};
    // M[count] = ⌈2^{{ k }} / count⌉ (count = 0: no detection, tdc unused).
    reg [{{ mw - 1 }}:0] recip;
    always @* begin
        case (count)
{%- for e in table %}
            {{ cw }}'d{{ e.0 }}: recip = {{ mw }}'d{{ e.1 }};
{%- endfor %}
            default: recip = {{ mw }}'d0;
        endcase
    end
    // x = s + ⌊n/2⌋ < n·2^{{ t }} fits the sum's {{ sw }} bits.
    wire [{{ sw - 1 }}:0] x = sum + { {{ sw - cw + 1 }}'d0, count[{{ cw - 1 }}:1] };
    /* verilator lint_off UNUSEDSIGNAL */
    wire [{{ sw + mw - 1 }}:0] product = { {{ mw }}'d0, x } * { {{ sw }}'d0, recip };
    /* verilator lint_on UNUSEDSIGNAL */
{%- if and_valid %}
    // DELIBERATELY BROKEN: valid only when every SPAD is.
    assign valid = &spad_valid;
{%- else %}
    assign valid = |spad_valid;
{%- endif %}
    assign tdc = product[{{ k + t - 1 }}:{{ k }}];
endmodule

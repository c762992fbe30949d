{{ header }}
// The pixel of docs/pixel-contract.md, verbatim: zoom, 1NN hold with priming,{% if fourier %} shift
// prefilter (arithmetic shift),{% else %} Haar signs from the latched pulse index,{% endif %} {{ r }} registers of {{ w }} bits
// served by {{ a }} shared adder(s) over {{ k }} slot(s) per pulse, readout-and-clear, and
// the saturating refused-pulse counter.
module {{ name }} (
    input  wire clk,
    input  wire rst,
    input  wire pulse,
    input  wire valid,
    input  wire [{{ t - 1 }}:0] tdc,
{%- if fourier %}
    input  wire [{{ r - 1 }}:0] rom_word,
{%- endif %}
    input  wire readout,
{%- if dbuf %}
    input  wire swap,
{%- endif %}
    output wire ready,
    output reg  rd_valid,
    output reg  [{{ ib - 1 }}:0] rd_index,
    output reg  [{{ w - 1 }}:0] rd_data
);
    // ---- state (contract "State") ----
    reg primed;
    reg [{{ t }}:0] held;
    reg [{{ opw - 1 }}:0] op;
    reg acc_en;
    reg active;
    reg [{{ sw - 1 }}:0] slot;
    reg rd_active;
    reg [{{ ib - 1 }}:0] rd_ptr;
    reg [{{ w - 1 }}:0] refused;
{%- if fourier %}
    reg [{{ xw - 1 }}:0] x;
    reg [{{ r - 1 }}:0] bits;
{%- else %}
    reg [{{ nlw - 1 }}:0] n_lat;  // pulse index bits log2(N)-1 .. log2(N)-U-1: all the signs use
    reg [{{ ln }}:0] pcount;
{%- endif %}
    // The register file. Public so the co-simulation harness can observe its writes.
{%- if clock_gated || latch %}
    // One clock per register: written from R processes, one element each (mem2reg: yosys
    // keeps each register as {% if latch %}latches{% else %}flops{% endif %} on its own gated clock).
    /* verilator lint_off MULTIDRIVEN */
    (* mem2reg *) reg [{{ w - 1 }}:0] y [0:{{ r - 1 }}] /*verilator public_flat_rd*/;
    /* verilator lint_on MULTIDRIVEN */
{%- else %}
    reg [{{ w - 1 }}:0] y [0:{{ r - 1 }}] /*verilator public_flat_rd*/;
{%- endif %}
{%- if dbuf %}
    // The shadow copy (docs/pixel-contract.md "Double buffer"): the registers and the
    // status word as they stood at the last `swap` edge, which the readout streams while
    // the registers accumulate the next frame. No reset: the first readout follows a swap.
{%- for g in regs %}
    reg [{{ w - 1 }}:0] sh_{{ g.r }};
{%- endfor %}
    reg [{{ w - 1 }}:0] sh_status;
{%- endif %}

    // ---- accept rule ----
{%- if dbuf %}
    // Double-buffered: the readout reads the shadow, so it neither waits for nor blocks
    // the pipeline, and a pulse during it is accepted.
    wire free = !active || slot == {{ sw }}'d{{ k - 1 }};
    assign ready = free;
    wire accept_ro = readout;
{%- else %}
    wire free = !rd_active && (!active || slot == {{ sw }}'d{{ k - 1 }});
    assign ready = free;
    wire accept_ro = readout && free;
{%- endif %}
{%- if fourier %}
    wire accept_pulse = pulse && free{% if !dbuf %} && !readout{% endif %};
{%- else %}
{%- if mutation == "haar_frame_limit" %}
    wire accept_pulse = pulse && free{% if !dbuf %} && !readout{% endif %};
{%- else %}
    wire accept_pulse = pulse && free{% if !dbuf %} && !readout{% endif %} && (pcount != {{ ln + 1 }}'d{{ n }});
{%- endif %}
{%- endif %}
    wire refuse = pulse && !accept_pulse;
    wire status_edge = rd_active && (rd_ptr == {{ ib }}'d{{ r }});

    // ---- zoom: d = tdc - Z in T+1 bits ----
    wire [{{ t }}:0] d = {1'b0, tdc} - {{ t + 1 }}'d{{ z }};
{%- if fourier %}

    // ---- shift prefilter: x_new = x + (((held << F) - x) >>> S), in T+2+F bits ----
{%- if f > 0 %}
    wire [{{ xw - 1 }}:0] held_f = {held, {{ f }}'d0};
    wire [{{ xw - 1 }}:0] d_f = {d, {{ f }}'d0};
{%- else %}
    wire [{{ xw - 1 }}:0] held_f = held;
    wire [{{ xw - 1 }}:0] d_f = d;
{%- endif %}
    wire [{{ xw }}:0] diff = {held_f[{{ xw - 1 }}], held_f} - {x[{{ xw - 1 }}], x};
{%- if mutation == "logical_shift" %}
    wire [{{ xw }}:0] step = diff >> {{ s }};
{%- else if round_half > 0 %}
    // Prefilter rounding "nearest": 2^(S-1) added before the shift (round half up), one
    // bit wider so the sum cannot wrap; the step lies between 0 and diff, so its top bit
    // is the sign and is dropped.
    wire [{{ xw + 1 }}:0] diff_r = {diff[{{ xw }}], diff} + {{ xw + 2 }}'d{{ round_half }};
    /* verilator lint_off UNUSEDSIGNAL */
    wire [{{ xw + 1 }}:0] step_r = $signed(diff_r) >>> {{ s }};
    /* verilator lint_on UNUSEDSIGNAL */
    wire [{{ xw }}:0] step = step_r[{{ xw }}:0];
{%- else %}
    wire [{{ xw }}:0] step = $signed(diff) >>> {{ s }};
{%- endif %}
    // The contract bounds x_new between x and held << F, so the sum's top bit equals bit
    // T+F and only the low T+1+F bits are kept.
    /* verilator lint_off UNUSEDSIGNAL */
    wire [{{ xw }}:0] x_sum = {x[{{ xw - 1 }}], x} + step;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [{{ xw - 1 }}:0] x_new = x_sum[{{ xw - 1 }}:0];
{%- if gs > 0 %}
    // Register operand (contract "register_frac_bits"): op = x_new >>> (F-G), G = {{ g }} of
    // the F = {{ f }} fraction bits. An arithmetic (floor) shift of a value that is then
    // sign-extended is the slice above its {{ gs }} low bits, so op and every register are
    // {{ gs }} bits narrower than x; the prefilter itself keeps all F bits.
    wire [{{ opw - 1 }}:0] op_new = x_new[{{ xw - 1 }}:{{ gs }}];
{%- endif %}
{%- else %}

    // ---- 1NN hold value of this pulse (Haar uses it directly as the operand) ----
{%- if mutation == "hold_invalid" %}
    wire [{{ t }}:0] h_new = d;
{%- else %}
    wire [{{ t }}:0] h_new = valid ? d : held;
{%- endif %}
{%- endif %}

    // ---- shared adders, pipelined (contract "Pipeline"): adder a serves operation
    // slot*A + a. Read stage: at every edge adder a reads the register and sign of its
    // operation at the next edge (slot+1 of this pulse, or slot 0 of a pulse accepted now,
    // decoded from the values being latched), so the write edge adds yin_a +/- op with no
    // register-file multiplexer before the adder. ----
    wire nx_same = active && slot != {{ sw }}'d{{ k - 1 }};
    wire [{{ sw - 1 }}:0] nslot = nx_same ? slot + {{ sw }}'d1 : {{ sw }}'d0;
{%- if fourier %}
    wire [{{ r - 1 }}:0] bits_nx = nx_same ? bits : rom_word;
{%- else %}
    wire [{{ nlw - 1 }}:0] n_nx = nx_same ? n_lat : pcount[{{ ln - 1 }}:{{ nlo }}];
{%- endif %}
    wire [{{ w - 1 }}:0] opx = {{ opx }};
{%- for ad in adders %}
    reg [{{ w - 1 }}:0] yin_{{ ad.a }};  // read stage: Y of the next operation
    reg add_{{ ad.a }};                  // read stage: its sign (1 = add)
    reg [{{ w - 1 }}:0] rd_{{ ad.a }};
    reg sg_{{ ad.a }};
    always @* begin
        rd_{{ ad.a }} = {{ w }}'d0;
        sg_{{ ad.a }} = 1'b0;
        case (nslot)
{%- for c in ad.cases %}
{%- if c.sel.is_empty() %}
            {{ sw }}'d{{ c.slot }}: begin rd_{{ ad.a }} = y[{{ c.entries[0].1 }}]; sg_{{ ad.a }} = {{ c.add }}; end
{%- else %}
            {{ sw }}'d{{ c.slot }}: begin
                sg_{{ ad.a }} = {{ c.add }};
                case ({{ c.sel }})
{%- for e in c.entries %}
                    {{ c.sel_bits }}'d{{ e.0 }}: rd_{{ ad.a }} = y[{{ e.1 }}];
{%- endfor %}
{%- if c.partial %}
                    default: rd_{{ ad.a }} = {{ w }}'d0;
{%- endif %}
                endcase
            end
{%- endif %}
{%- endfor %}
            // The read-ahead slot is 0..K-1 for every K: this arm is unreachable, kept so the
            // case is full for lint, and left out of line coverage.
            // verilator coverage_off
            default: begin rd_{{ ad.a }} = {{ w }}'d0; sg_{{ ad.a }} = 1'b0; end
            // verilator coverage_on
        endcase
    end
{%- if mutation == "sign_flip" %}
    wire [{{ w - 1 }}:0] sum_{{ ad.a }} = add_{{ ad.a }} ? (yin_{{ ad.a }} - opx) : (yin_{{ ad.a }} + opx);
{%- else if mutation == "hold_on_overflow" %}
    // FAULT: an accumulate that leaves W bits holds the register instead of wrapping.
    wire [{{ w }}:0] sx_{{ ad.a }} = add_{{ ad.a }} ? ({yin_{{ ad.a }}[{{ w - 1 }}], yin_{{ ad.a }}} + {opx[{{ w - 1 }}], opx}) : ({yin_{{ ad.a }}[{{ w - 1 }}], yin_{{ ad.a }}} - {opx[{{ w - 1 }}], opx});
    wire [{{ w - 1 }}:0] sum_{{ ad.a }} = (sx_{{ ad.a }}[{{ w }}] != sx_{{ ad.a }}[{{ w - 1 }}]) ? yin_{{ ad.a }} : sx_{{ ad.a }}[{{ w - 1 }}:0];
{%- else %}
    wire [{{ w - 1 }}:0] sum_{{ ad.a }} = add_{{ ad.a }} ? (yin_{{ ad.a }} + opx) : (yin_{{ ad.a }} - opx);
{%- endif %}
    always @(posedge clk) begin
        if (rst) begin
            yin_{{ ad.a }} <= {{ w }}'d0;
            add_{{ ad.a }} <= 1'b0;
        end else begin
{%- if !ad.fwd.is_empty() && mutation != "missing_forward" %}
            // Forward (K = 1): the previous pulse writes the register read now.
            yin_{{ ad.a }} <= ({{ ad.fwd }}) ? sum_{{ ad.a }} : rd_{{ ad.a }};
{%- else %}
            yin_{{ ad.a }} <= rd_{{ ad.a }};
{%- endif %}
            add_{{ ad.a }} <= sg_{{ ad.a }};
        end
    end
{%- endfor %}

    // ---- register writes: accumulate (slot's adder) or readout clear ----
    wire [{{ r - 1 }}:0] we_c;
{%- for g in regs %}
{%- if dbuf %}
    // Double-buffered: the swap clears the register (it was copied to the shadow).
    assign we_c[{{ g.r }}] = (active && acc_en && {{ g.sel }}) || swap;
{%- else if mutation == "readout_clear" %}
    assign we_c[{{ g.r }}] = active && acc_en && {{ g.sel }};
{%- else if mutation == "enable_decode" %}
    assign we_c[{{ g.r }}] = (active && {{ g.sel }}) || (rd_active && rd_ptr == {{ ib }}'d{{ g.r }});
{%- else %}
    assign we_c[{{ g.r }}] = (active && acc_en && {{ g.sel }}) || (rd_active && rd_ptr == {{ ib }}'d{{ g.r }});
{%- endif %}
{%- if !latch || mutation == "schedule_late" %}
    wire [{{ w - 1 }}:0] wval_{{ g.r }} = {% if dbuf %}swap{% else %}rd_active{% endif %} ? {{ w }}'d0 : sum_{{ g.adder }};
{%- endif %}
{%- endfor %}
{%- if mutation == "schedule_late" %}
    // FAULT: writes land one edge late.
    reg [{{ r - 1 }}:0] we /*verilator public_flat_rd*/;
{%- for g in regs %}
    reg [{{ w - 1 }}:0] wlate_{{ g.r }};
{%- endfor %}
    always @(posedge clk) begin
        if (rst) begin
            we <= {{ r }}'d0;
        end else begin
            we <= we_c;
        end
{%- for g in regs %}
        wlate_{{ g.r }} <= wval_{{ g.r }};
{%- endfor %}
    end
{%- else %}
    wire [{{ r - 1 }}:0] we /*verilator public_flat_rd*/ = we_c;
{%- endif %}
{%- if clock_gated %}
    // Clock-gated register file (pixel.register_file = "clock_gated", docs/pixel-contract.md
    // "Register file"): register r is clocked by clk gated by its write enable (and by
    // reset, so reset still clears it), so its flops have no enable multiplexer. The gate
    // passes the same clk edge at which a flop with enable would load: same update.
{%- for g in regs %}
    wire gclk_{{ g.r }};
    {{ name }}_clock_gate cg_{{ g.r }} (.clk(clk), .en(we[{{ g.r }}] | rst), .gclk(gclk_{{ g.r }}));
    always @(posedge gclk_{{ g.r }}) begin
        if (rst) y[{{ g.r }}] <= {{ w }}'d0;
{%- if mutation == "schedule_late" %}
        else y[{{ g.r }}] <= wlate_{{ g.r }};
{%- else if mutation == "narrow_register" && g.r == 0 %}
        else y[0] <= {wval_0[{{ w - 2 }}], wval_0[{{ w - 2 }}:0]};
{%- else %}
        else y[{{ g.r }}] <= wval_{{ g.r }};
{%- endif %}
    end
{%- endfor %}
{%- else if latch %}
    // Latch register file (pixel.register_file = "latch", docs/pixel-contract.md "Register
    // file"): register r is W transparent-high latches enabled by clk's low phase gated by
    // the write enable of the last rising edge. A write decided at rising edge t (we[r] high
    // before it) is captured at t: its enable in we_q, its value in its adder's word wd_a
    // (readout clears and reset as 0). The latches pass it while clk is low and close at
    // edge t+1, so the register holds its new value from the falling edge after t, and at
    // every rising edge it holds what a flop register file holds. The latch input is a
    // flop, never the register itself: no loop through the adder while transparent, and
    // no register is transparent at a rising edge, where it is read.
    wire clk_n = ~clk;
    reg [{{ r - 1 }}:0] we_q;
{%- for ad in adders %}
    reg [{{ w - 1 }}:0] wd_{{ ad.a }};
{%- endfor %}
    always @(posedge clk) begin
        we_q <= we | { {{- r }}{rst}};
{%- for ad in adders %}
        wd_{{ ad.a }} <= (rst || {% if dbuf %}swap{% else %}rd_active{% endif %}) ? {{ w }}'d0 : sum_{{ ad.a }};
{%- endfor %}
    end
{%- for g in regs %}
    wire gclk_{{ g.r }};
    {{ name }}_clock_gate cg_{{ g.r }} (.clk(clk_n), .en(we_q[{{ g.r }}]), .gclk(gclk_{{ g.r }}));
    /* verilator lint_off LATCH */
    always @* begin
{%- if mutation == "narrow_register" && g.r == 0 %}
        if (gclk_0) y[0] = {wd_{{ g.adder }}[{{ w - 2 }}], wd_{{ g.adder }}[{{ w - 2 }}:0]};
{%- else %}
        if (gclk_{{ g.r }}) y[{{ g.r }}] = wd_{{ g.adder }};
{%- endif %}
    end
    /* verilator lint_on LATCH */
{%- endfor %}
{%- else %}
    always @(posedge clk) begin
{%- if mutation == "reset_when_idle" %}
        // FAULT: reset clears the register file only when no pulse is in flight.
        if (rst && !active) begin
{%- else %}
        if (rst) begin
{%- endif %}
{%- for g in regs %}
            y[{{ g.r }}] <= {{ w }}'d0;
{%- endfor %}
        end else begin
{%- for g in regs %}
{%- if mutation == "schedule_late" %}
            if (we[{{ g.r }}]) y[{{ g.r }}] <= wlate_{{ g.r }};
{%- else if mutation == "narrow_register" && g.r == 0 %}
            if (we[0]) y[0] <= {wval_0[{{ w - 2 }}], wval_0[{{ w - 2 }}:0]};
{%- else %}
            if (we[{{ g.r }}]) y[{{ g.r }}] <= wval_{{ g.r }};
{%- endif %}
{%- endfor %}
        end
    end
{%- endif %}

    // ---- readout multiplexer ----
    reg [{{ w - 1 }}:0] rd_mux;
    always @* begin
        case (rd_ptr)
{%- for g in regs %}
            {{ ib }}'d{{ g.r }}: rd_mux = {% if dbuf %}sh_{{ g.r }}{% else %}y[{{ g.r }}]{% endif %};
{%- endfor %}
            default: rd_mux = {{ w }}'d0;
        endcase
    end

    // ---- control, hold, prefilter ----
    always @(posedge clk) begin
        if (rst) begin
{%- if mutation != "reset_primed" %}
            primed <= 1'b0;
{%- endif %}
            held <= {{ t + 1 }}'d0;
            op <= {{ opw }}'d0;
            acc_en <= 1'b0;
            active <= 1'b0;
            slot <= {{ sw }}'d0;
            rd_active <= 1'b0;
            rd_ptr <= {{ ib }}'d0;
            refused <= {{ w }}'d0;
            rd_valid <= 1'b0;
            rd_index <= {{ ib }}'d0;
            rd_data <= {{ w }}'d0;
{%- if fourier %}
            x <= {{ xw }}'d0;
            bits <= {{ r }}'d0;
{%- else %}
            n_lat <= {{ nlw }}'d0;
            pcount <= {{ ln + 1 }}'d0;
{%- endif %}
        end else begin
            if (active) begin
                if (slot == {{ sw }}'d{{ k - 1 }}) active <= 1'b0;
                slot <= slot + {{ sw }}'d1;
            end
            if (rd_active) begin
                rd_valid <= 1'b1;
                if (!status_edge) begin
                    rd_data <= rd_mux;
                    rd_index <= rd_ptr;
                    rd_ptr <= rd_ptr + {{ ib }}'d1;
                end else begin
{%- if mutation == "status_word" %}
                    rd_data <= rd_mux;
{%- else %}
                    rd_data <= {% if dbuf %}sh_status{% else %}refused{% endif %};
{%- endif %}
                    rd_index <= {{ ib }}'d{{ r }};
                    rd_active <= 1'b0;
{%- if !fourier && !dbuf %}
                    pcount <= {{ ln + 1 }}'d0;
{%- endif %}
                end
            end else begin
                rd_valid <= 1'b0;
            end
            if (accept_ro) begin
                rd_active <= 1'b1;
                rd_ptr <= {{ ib }}'d0;
            end
{%- if dbuf %}
            if (swap) begin
                refused <= {{ w }}'d0;
{%- else %}
            if (status_edge) begin
                refused <= { {{- w - 1 }}'d0, refuse};
{%- endif %}
{%- if mutation != "refused_counter" %}
            end else if (refuse && refused != {{ "{" }}{{ w }}{1'b1}}) begin
                refused <= refused + {{ w }}'d1;
{%- endif %}
            end
            if (accept_pulse) begin
{%- if fourier %}
                if (primed) begin
                    x <= x_new;
                    op <= {% if gs > 0 %}op_new{% else %}x_new{% endif %};
                    acc_en <= 1'b1;
                end else begin
                    acc_en <= 1'b0;
                end
{%- if mutation == "hold_invalid" %}
                held <= d;
{%- else %}
                if (valid) held <= d;
{%- endif %}
{%- if mutation == "prime_on_miss" %}
                if (!primed) begin
{%- else %}
                if (valid && !primed) begin
{%- endif %}
                    primed <= 1'b1;
                    x <= d_f;
                end
                bits <= rom_word;
{%- else %}
                held <= h_new;
                op <= h_new;
                acc_en <= primed || valid;
{%- if mutation == "prime_on_miss" %}
                primed <= 1'b1;
{%- else %}
                if (valid) primed <= 1'b1;
{%- endif %}
                n_lat <= pcount[{{ ln - 1 }}:{{ nlo }}];
                pcount <= pcount + {{ ln + 1 }}'d1;
{%- endif %}
                active <= 1'b1;
                slot <= {{ sw }}'d0;
            end
{%- if dbuf && !fourier %}
            // The next frame's pulse count starts at the swap.
            if (swap) pcount <= {{ ln + 1 }}'d0;
{%- endif %}
        end
    end
{%- if dbuf %}

    // ---- the swap: the registers and the status word into the shadow ----
    always @(posedge clk) begin
        if (swap) begin
{%- for g in regs %}
            sh_{{ g.r }} <= y[{{ g.r }}];
{%- endfor %}
            sh_status <= refused;
        end
    end
{%- endif %}
endmodule
{%- if clock_gated || latch %}

// The clock gate of one register (pixel.register_file = "clock_gated", or "latch" on the
// inverted clock, where it gates the low phase the latches are transparent in): the standard
// latch-based integrated clock gate. The latch is transparent while clk is low, so the
// enable settled during a cycle is held through the high phase and gclk carries exactly
// the rising edges of clk the enable selects, without glitches. This body is for
// simulation; synthesis maps the module onto the liberty's clock-gating cell (or its
// latch and an AND gate). A second module in the file: named after the pixel, not the file.
/* verilator lint_off DECLFILENAME */
module {{ name }}_clock_gate (
    input  wire clk,
    input  wire en,
    output wire gclk
);
    reg en_l;
    /* verilator lint_off LATCH */
    always @(clk or en) begin
        if (!clk) en_l = en;
    end
    /* verilator lint_on LATCH */
    assign gclk = clk & en_l;
endmodule
/* verilator lint_on DECLFILENAME */
{%- endif %}
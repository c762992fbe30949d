{{ header }}
// The array of docs/pixel-contract.md "Array": {{ rows }} x {{ cols }} instances of the one pixel,
// one probe ROM{% if !fourier %} (none: Haar){% endif %} and one sequencer at the root. The sequencer's
// `pulse`{% if fourier %}, `rom_word`{% endif %} and readout strobes reach every pixel through two registered
// fan-out stages (the root, then one per row). After {{ n }} pulses one every {{ c }} cycles,
// the readout phase reads the pixels one at a time, row-major, one every {{ s }} cycles
// ({{ rows * cols }} x {{ s }} + 1 cycles, no pulse presented): a row select puts the pixel on
// its column bus, the selected column's words are captured into a readout buffer, and
// the buffer drains onto the {{ b }}-bit port, {{ k }} beat(s) per word (least significant
// first; registers sign-extended, the status word zero-extended), one beat every {{ g }}
// cycle(s). `pulse_o` tells the TDCs (and a testbench) that the pixels sample `valid` and
// `tdc` this cycle; {% if sp > 1 %}each pixel is a superpixel of
// {{ sp }} x {{ sp }} SPADs: `valid` and `tdc` are per SPAD, SPAD (sr, sc) of the {{ trows * sp }} x {{ scols }} SPAD grid{% if let Some(t) = tile %}
// of the TILE of rows {{ t.0 }}..{{ t.0 + trows - 1 }}, columns {{ t.1 }}..{{ t.1 + tcols - 1 }} (the sequencer, broadcast and readout of the whole array,
// the other pixels absent: their slots carry no beat){% endif %} is bit sr*{{ scols }}+sc of `valid` and that field of
// `tdc`, and pixel (r, c) averages SPADs (r*{{ sp }}+i, c*{{ sp }}+j) through one `{{ sp_name }}` (combinational: it
// samples the average as it would one SPAD's).{% else %}{% if let Some(t) = tile %}this is the TILE of rows {{ t.0 }}..{{ t.0 + trows - 1 }}, columns {{ t.1 }}..{{ t.1 + tcols - 1 }}
// only (the sequencer, broadcast and readout of the whole array, the other pixels absent:
// their slots carry no beat); its pixel (r, c) is bit (r-{{ t.0 }})*{{ tcols }}+(c-{{ t.1 }}) of `valid` and that field of `tdc`.{% else %}pixel (r, c) is bit r*{{ cols }}+c of `valid` and field r*{{ cols }}+c of `tdc`.{% endif %}{% endif %}
module {{ name }} (
    input  wire clk,
    input  wire rst,
    input  wire [{{ nin - 1 }}:0] valid,
    input  wire [{{ nin * t - 1 }}:0] tdc,
    output wire pulse_o,
    output wire ready,
    output reg  ro_valid,
    output reg  [{{ b - 1 }}:0] ro_data
);
    // ---- the sequencer (root) ----
    reg ro_phase;
    reg [{{ pw - 1 }}:0] ph;
    reg [{{ nw - 1 }}:0] pidx;
    reg [{{ qw - 1 }}:0] q;
    reg [{{ scw - 1 }}:0] sc;
    reg [{{ rw - 1 }}:0] qr;
    reg [{{ cw - 1 }}:0] qc;
{%- if dbuf %}
    // Double-buffered (docs/pixel-contract.md "Double buffer"): after the frame's
    // {{ n }} pulses the sequencer holds {{ idle + 1 }} cycle(s) (the swap cycle, then the wait until
    // the last frame's readout is done), while the readout walks the pixels beside the
    // next frame's pulses; the swap is its first cycle.
    reg hold;
    reg [{{ hw - 1 }}:0] wt;
    wire s_pulse = !rst && !hold && (ph == {{ pw }}'d0);
    wire s_swap = !rst && ro_phase && (q == {{ qw }}'d0) && (sc == {{ scw }}'d0);
{%- else %}
    wire s_pulse = !rst && !ro_phase && (ph == {{ pw }}'d0);
{%- endif %}
    wire s_ro = !rst && ro_phase && (sc == {{ scw }}'d0) && (q != {{ qw }}'d{{ np }});
{%- if mutation == "order_swap" %}
    // DELIBERATELY BROKEN: the readout order swaps its first two pixels.
    wire [{{ rw - 1 }}:0] s_row = (q == {{ qw }}'d0) ? {{ rw }}'d{{ swap_r1 }} : (q == {{ qw }}'d1) ? {{ rw }}'d{{ swap_r0 }} : qr;
    wire [{{ cw - 1 }}:0] s_col = (q == {{ qw }}'d0) ? {{ cw }}'d{{ swap_c1 }} : (q == {{ qw }}'d1) ? {{ cw }}'d{{ swap_c0 }} : qc;
{%- else %}
    wire [{{ rw - 1 }}:0] s_row = qr;
    wire [{{ cw - 1 }}:0] s_col = qc;
{%- endif %}
{%- if fourier %}
    reg [{{ aw - 1 }}:0] addr;
    wire [{{ r - 1 }}:0] rom_word;
    {{ rom_name }} u_rom (.addr(addr), .word(rom_word));
{%- endif %}

{%- if dbuf %}

    always @(posedge clk) begin
        if (rst) begin
            ro_phase <= 1'b0;
            ph <= {{ pw }}'d0;
            pidx <= {{ nw }}'d0;
            q <= {{ qw }}'d0;
            sc <= {{ scw }}'d0;
            qr <= {{ rw }}'d0;
            qc <= {{ cw }}'d0;
            hold <= 1'b0;
            wt <= {{ hw }}'d0;
{%- if fourier %}
            addr <= {{ aw }}'d0;
{%- endif %}
        end else begin
            // The readout walker.
            if (ro_phase) begin
                if (q == {{ qw }}'d{{ np }}) begin
                    ro_phase <= 1'b0;
                end else if (sc == {{ scw }}'d{{ s - 1 }}) begin
                    sc <= {{ scw }}'d0;
                    q <= q + {{ qw }}'d1;
                    if (qc == {{ cw }}'d{{ cols - 1 }}) begin
                        qc <= {{ cw }}'d0;
                        qr <= qr + {{ rw }}'d1;
                    end else begin
                        qc <= qc + {{ cw }}'d1;
                    end
                end else begin
                    sc <= sc + {{ scw }}'d1;
                end
            end
            // The pulses; the frame's end starts the walker (it has finished: D <= the
            // frame period), after it in the block so the restart wins.
            if (hold) begin
                if (wt == {{ hw }}'d0) hold <= 1'b0;
                else wt <= wt - {{ hw }}'d1;
            end else if (ph == {{ pw }}'d{{ c - 1 }}) begin
                ph <= {{ pw }}'d0;
{%- if fourier %}
                addr <= (addr == {{ aw }}'d{{ l - 1 }}) ? {{ aw }}'d0 : addr + {{ aw }}'d1;
{%- endif %}
                if (pidx == {{ nw }}'d{{ n - 1 }}) begin
                    pidx <= {{ nw }}'d0;
                    hold <= 1'b1;
                    wt <= {{ hw }}'d{{ idle }};
                    ro_phase <= 1'b1;
                    q <= {{ qw }}'d0;
                    sc <= {{ scw }}'d0;
                    qr <= {{ rw }}'d0;
                    qc <= {{ cw }}'d0;
{%- if fourier %}
                    addr <= {{ aw }}'d0;
{%- endif %}
                end else begin
                    pidx <= pidx + {{ nw }}'d1;
                end
            end else begin
                ph <= ph + {{ pw }}'d1;
            end
        end
    end
{%- else %}

    always @(posedge clk) begin
        if (rst) begin
            ro_phase <= 1'b0;
            ph <= {{ pw }}'d0;
            pidx <= {{ nw }}'d0;
            q <= {{ qw }}'d0;
            sc <= {{ scw }}'d0;
            qr <= {{ rw }}'d0;
            qc <= {{ cw }}'d0;
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
                    q <= {{ qw }}'d0;
                    sc <= {{ scw }}'d0;
                    qr <= {{ rw }}'d0;
                    qc <= {{ cw }}'d0;
{%- if fourier %}
                    addr <= {{ aw }}'d0;
{%- endif %}
                end else begin
                    pidx <= pidx + {{ nw }}'d1;
                end
            end else begin
                ph <= ph + {{ pw }}'d1;
            end
        end else if (q == {{ qw }}'d{{ np }}) begin
            ro_phase <= 1'b0;
        end else if (sc == {{ scw }}'d{{ s - 1 }}) begin
            sc <= {{ scw }}'d0;
            q <= q + {{ qw }}'d1;
            if (qc == {{ cw }}'d{{ cols - 1 }}) begin
                qc <= {{ cw }}'d0;
                qr <= qr + {{ rw }}'d1;
            end else begin
                qc <= qc + {{ cw }}'d1;
            end
        end else begin
            sc <= sc + {{ scw }}'d1;
        end
    end
{%- endif %}

    // ---- broadcast stage 1: the root's registers ----
    reg b_pulse;
    reg b_ro;
{%- if dbuf %}
    reg b_swap;
{%- endif %}
    reg [{{ rw - 1 }}:0] b_row;
    reg [{{ cw - 1 }}:0] b_col;
{%- if fourier %}
    reg [{{ r - 1 }}:0] b_word;
{%- endif %}
    always @(posedge clk) begin
        if (rst) begin
            b_pulse <= 1'b0;
            b_ro <= 1'b0;
{%- if dbuf %}
            b_swap <= 1'b0;
{%- endif %}
            b_row <= {{ rw }}'d0;
            b_col <= {{ cw }}'d0;
{%- if fourier %}
            b_word <= {{ r }}'d0;
{%- endif %}
        end else begin
            b_pulse <= s_pulse;
            b_ro <= s_ro;
{%- if dbuf %}
            b_swap <= s_swap;
{%- endif %}
            b_row <= s_row;
            b_col <= s_col;
{%- if fourier %}
            b_word <= rom_word;
{%- endif %}
        end
    end

    // ---- broadcast stage 2: one register per row (and the TDCs' strobe) ----
    reg o_pulse;
    assign pulse_o = o_pulse;
    reg [{{ trows - 1 }}:0] r_pulse;
    reg [{{ trows - 1 }}:0] r_ro;
{%- if dbuf %}
    reg [{{ trows - 1 }}:0] r_swap;
{%- endif %}
{%- if mutation == "swap_late" %}
    // DELIBERATELY BROKEN: the swap passes one extra register (the shadow a cycle late).
    reg late_swap;
    always @(posedge clk) begin
        if (rst) late_swap <= 1'b0;
        else late_swap <= b_swap;
    end
{%- endif %}
    reg [{{ trows * cw - 1 }}:0] r_col;
{%- if fourier %}
    reg [{{ trows * r - 1 }}:0] r_word;
{%- endif %}
{%- if mutation == "row_late" %}
    // DELIBERATELY BROKEN: one row's broadcast passes one extra register.
    reg late_pulse;
{%- if fourier %}
    reg [{{ r - 1 }}:0] late_word;
{%- endif %}
{%- endif %}
    // Each row's stage is its own register (`keep`): the rows' stages take the same value,
    // and a synthesis tool merges equal registers unless told not to — into one register
    // driving every pixel, the fan-out the stages are there to split.
    (* keep *) always @(posedge clk) begin
        if (rst) o_pulse <= 1'b0;
        else o_pulse <= b_pulse;
    end
{%- for row in rows_t %}
    (* keep *) always @(posedge clk) begin
        if (rst) begin
            r_pulse[{{ row.lr }}] <= 1'b0;
            r_ro[{{ row.lr }}] <= 1'b0;
{%- if dbuf %}
            r_swap[{{ row.lr }}] <= 1'b0;
{%- endif %}
            r_col[{{ row.lr * cw }} +: {{ cw }}] <= {{ cw }}'d0;
{%- if fourier %}
            r_word[{{ row.lr * r }} +: {{ r }}] <= {{ r }}'d0;
{%- endif %}
{%- if row.late %}
            late_pulse <= 1'b0;
{%- if fourier %}
            late_word <= {{ r }}'d0;
{%- endif %}
{%- endif %}
        end else begin
{%- if row.late %}
            late_pulse <= b_pulse;
            r_pulse[{{ row.lr }}] <= late_pulse;
{%- else %}
            r_pulse[{{ row.lr }}] <= b_pulse;
{%- endif %}
            r_ro[{{ row.lr }}] <= b_ro && (b_row == {{ rw }}'d{{ row.row }});
{%- if mutation == "swap_late" %}
            r_swap[{{ row.lr }}] <= late_swap;
{%- else if dbuf %}
            r_swap[{{ row.lr }}] <= b_swap;
{%- endif %}
            r_col[{{ row.lr * cw }} +: {{ cw }}] <= b_col;
{%- if fourier %}
{%- if row.late %}
            late_word <= b_word;
            r_word[{{ row.lr * r }} +: {{ r }}] <= late_word;
{%- else %}
            r_word[{{ row.lr * r }} +: {{ r }}] <= b_word;
{%- endif %}
{%- endif %}
        end
    end
{%- endfor %}

    // ---- the pixels ----
    wire [{{ npt - 1 }}:0] p_ready;
    wire [{{ npt - 1 }}:0] p_valid;
    wire [{{ npt * ib - 1 }}:0] p_index;
    wire [{{ npt * w - 1 }}:0] p_data;
    assign ready = &p_ready;
{%- if sp > 1 %}
    // Each pixel's {{ sp }} x {{ sp }} SPADs averaged into its (valid, tdc).
    wire [{{ npt - 1 }}:0] s_valid;
    wire [{{ npt * t - 1 }}:0] s_tdc;
{%- for px in pixels %}
    {{ sp_name }} u_superpixel_{{ px.row }}_{{ px.col }} (
        .spad_valid({ {% for s in px.spads.iter().rev() %}valid[{{ s }}]{% if !loop.last %}, {% endif %}{% endfor %} }),
        .spad_tdc({ {% for s in px.spads.iter().rev() %}tdc[{{ s * t }} +: {{ t }}]{% if !loop.last %}, {% endif %}{% endfor %} }),
        .valid(s_valid[{{ px.i }}]),
        .tdc(s_tdc[{{ px.i * t }} +: {{ t }}])
    );
{%- endfor %}
{%- endif %}
{%- for px in pixels %}
    {{ pixel_name }} u_pixel_{{ px.row }}_{{ px.col }} (
        .clk(clk),
        .rst(rst),
        .pulse(r_pulse[{{ px.lr }}]),
        .valid({{ px.valid }}),
        .tdc({{ px.tdc }}),
{%- if fourier %}
        .rom_word(r_word[{{ px.lr * r }} +: {{ r }}]),
{%- endif %}
        .readout(r_ro[{{ px.lr }}] && (r_col[{{ px.lr * cw }} +: {{ cw }}] == {{ cw }}'d{{ px.col }})),
{%- if dbuf %}
        .swap(r_swap[{{ px.lr }}]),
{%- endif %}
        .ready(p_ready[{{ px.i }}]),
        .rd_valid(p_valid[{{ px.i }}]),
        .rd_index(p_index[{{ px.i * ib }} +: {{ ib }}]),
        .rd_data(p_data[{{ px.i * w }} +: {{ w }}])
    );
{%- endfor %}

    // ---- the read select: a row onto the column buses, a column onto the capture ----
    // The strobe's root registers, two more stages on: the select changes the cycle after
    // the pixel takes its strobe, when its first word is still a cycle away.
    reg d_ro;
    reg [{{ rw - 1 }}:0] d_row;
    reg [{{ cw - 1 }}:0] d_col;
    reg e_ro;
    reg [{{ rw - 1 }}:0] e_row;
    reg [{{ cw - 1 }}:0] e_col;
    reg [{{ trows - 1 }}:0] m_row;
    reg [{{ cw - 1 }}:0] m_col;
    always @(posedge clk) begin
        if (rst) begin
            d_ro <= 1'b0;
            d_row <= {{ rw }}'d0;
            d_col <= {{ cw }}'d0;
            e_ro <= 1'b0;
            e_row <= {{ rw }}'d0;
            e_col <= {{ cw }}'d0;
            m_row <= {{ trows }}'d0;
            m_col <= {{ cw }}'d0;
        end else begin
            d_ro <= b_ro;
            d_row <= b_row;
            d_col <= b_col;
            e_ro <= d_ro;
            e_row <= d_row;
            e_col <= d_col;
            if (e_ro) begin
                m_col <= e_col;
{%- for row in rows_t %}
{%- if row.stuck %}
                // DELIBERATELY BROKEN: row {{ row.row }} never leaves readout once selected.
                m_row[{{ row.lr }}] <= m_row[{{ row.lr }}] || (e_row == {{ rw }}'d{{ row.row }});
{%- else %}
                m_row[{{ row.lr }}] <= (e_row == {{ rw }}'d{{ row.row }});
{%- endif %}
{%- endfor %}
            end
        end
    end
    // Column buses: the OR of the selected row's pixels.
    wire [{{ tcols - 1 }}:0] bus_valid;
    wire [{{ tcols * ib - 1 }}:0] bus_index;
    wire [{{ tcols * w - 1 }}:0] bus_data;
{%- for col in columns %}
    assign bus_valid[{{ col.lc }}] = {{ col.valid }};
    assign bus_index[{{ col.lc * ib }} +: {{ ib }}] = {{ col.index }};
    assign bus_data[{{ col.lc * w }} +: {{ w }}] = {{ col.data }};
{%- endfor %}
    reg m_valid;
    reg [{{ ib - 1 }}:0] m_index;
    reg [{{ w - 1 }}:0] m_data;
    always @* begin
        case (m_col)
{%- for col in columns %}
            {{ cw }}'d{{ col.col }}: begin
                m_valid = bus_valid[{{ col.lc }}];
                m_index = bus_index[{{ col.lc * ib }} +: {{ ib }}];
                m_data = bus_data[{{ col.lc * w }} +: {{ w }}];
            end
{%- endfor %}
            default: begin
                m_valid = 1'b0;
                m_index = {{ ib }}'d0;
                m_data = {{ w }}'d0;
            end
        endcase
    end

    // ---- the readout buffer and the port ----
{%- for j in words %}
    reg [{{ w - 1 }}:0] rbuf_{{ j }};
{%- endfor %}
    reg dr_act;
    reg [{{ ib - 1 }}:0] dj;
{%- if k > 1 %}
    reg [{{ kw - 1 }}:0] dm;
{%- endif %}
{%- if g > 1 %}
    reg [{{ gw - 1 }}:0] dg;
    wire beat = dr_act && (dg == {{ gw }}'d0);
    wire step = dr_act && (dg == {{ gw }}'d{{ g - 1 }});
{%- else %}
    wire beat = dr_act;
    wire step = dr_act;
{%- endif %}
{%- if k > 1 %}
    wire last = (dj == {{ ib }}'d{{ r }}) && (dm == {{ kw }}'d{{ k - 1 }});
{%- else %}
    wire last = (dj == {{ ib }}'d{{ r }});
{%- endif %}
    reg [{{ w - 1 }}:0] dw;
    always @* begin
        case (dj)
{%- for j in words %}
            {{ ib }}'d{{ j }}: dw = rbuf_{{ j }};
{%- endfor %}
            default: dw = {{ w }}'d0;
        endcase
    end
{%- if kb > w %}
    // Registers sign-extended, the status word (index {{ r }}) zero-extended, to {{ kb }} bits.
    wire dsx = dw[{{ w - 1 }}] && (dj != {{ ib }}'d{{ r }});
    wire [{{ kb - 1 }}:0] dx = {{ dx_ext }};
{%- else %}
    wire [{{ kb - 1 }}:0] dx = dw;
{%- endif %}
    always @(posedge clk) begin
{%- for j in words %}
        if (m_valid && (m_index == {{ ib }}'d{{ j }})) begin
            rbuf_{{ j }} <= m_data;
        end
{%- endfor %}
    end
    always @(posedge clk) begin
        if (rst) begin
            dr_act <= 1'b0;
            dj <= {{ ib }}'d0;
{%- if k > 1 %}
            dm <= {{ kw }}'d0;
{%- endif %}
{%- if g > 1 %}
            dg <= {{ gw }}'d0;
{%- endif %}
            ro_valid <= 1'b0;
            ro_data <= {{ b }}'d0;
        end else begin
            ro_valid <= beat;
            if (beat) begin
{%- if k > 1 %}
                case (dm)
{%- for m in parts %}
                    {{ kw }}'d{{ m }}: ro_data <= dx[{{ m * b }} +: {{ b }}];
{%- endfor %}
                    default: ro_data <= {{ b }}'d0;
                endcase
{%- else %}
                ro_data <= dx;
{%- endif %}
            end
            if (m_valid && (m_index == {{ ib }}'d0)) begin
                // A pixel's word 0 is in the buffer: its drain starts at the next edge.
                dr_act <= 1'b1;
                dj <= {{ ib }}'d0;
{%- if k > 1 %}
                dm <= {{ kw }}'d0;
{%- endif %}
{%- if g > 1 %}
                dg <= {{ gw }}'d0;
{%- endif %}
            end else if (dr_act) begin
{%- if g > 1 %}
                dg <= step ? {{ gw }}'d0 : dg + {{ gw }}'d1;
{%- endif %}
                if (step) begin
                    if (last) begin
                        dr_act <= 1'b0;
{%- if k > 1 %}
                    end else if (dm == {{ kw }}'d{{ k - 1 }}) begin
                        dm <= {{ kw }}'d0;
                        dj <= dj + {{ ib }}'d1;
                    end else begin
                        dm <= dm + {{ kw }}'d1;
{%- else %}
                    end else begin
                        dj <= dj + {{ ib }}'d1;
{%- endif %}
                    end
                end
            end
        end
    end
endmodule

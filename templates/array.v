{{ header }}
// The array of docs/pixel-contract.md "Array": ROWS x COLS instances of the one pixel
// `{{ pixel_name }}`, one probe ROM{% if !fourier %} (none: Haar){% endif %} and the chip's one sequencer
// `{{ seq_name }}` at the root, written with generate loops over the parameters below: the
// file's size does not grow with the array. The sequencer's `pulse`{% if fourier %}, `rom_word`{% endif %} and
// readout strobes reach every pixel through two registered fan-out stages (the root, then
// one per row). After {{ n }} pulses one every {{ c }} cycles, the readout phase reads the pixels
// one at a time, row-major, one every SLOT = (R+1) x K x BEAT_CYCLES cycles ({{ r }} registers and
// the status word; ROWS x COLS x SLOT + 1 cycles{% if dbuf %}, beside the next frame's pulses: double-buffered{% else %}, no pulse presented{% endif %}): a row select puts the
// pixel on its column bus, the selected column's words are captured into a readout buffer,
// and the buffer drains onto the READOUT_BITS-bit port, K = ceil({{ w }} / READOUT_BITS) beat(s)
// per word (least significant first; registers sign-extended, the status word
// zero-extended), one beat every BEAT_CYCLES cycle(s). `pulse_o` tells the TDCs (and a
// testbench) that the pixels sample `valid` and `tdc` this cycle.
//
// Only the pixels of the TILE (rows TILE_ROW0 .. TILE_ROW0+TILE_ROWS-1, columns TILE_COL0 ..
// TILE_COL0+TILE_COLS-1; the whole array by default) are instantiated: the sequencer,
// broadcast and readout still walk the whole array, the absent pixels' slots carry no beat.
// The ports are per pixel of the tile{% if sp > 1 %} and per SPAD: each pixel is a superpixel of
// G x G = {{ sp }} x {{ sp }} SPADs, SPAD (sr, sc) of the tile's (TILE_ROWS*G) x (TILE_COLS*G) SPAD grid is
// bit sr*TILE_COLS*G+sc of `valid` and that field of `tdc`, and pixel (r, c) averages SPADs
// (r*G+i, c*G+j) through one `{{ sp_name }}` (combinational: it samples the average as it would
// one SPAD's){% else %}: the tile's pixel (r, c) is bit r*TILE_COLS+c of `valid` and that field of `tdc`{% endif %}.
// G and the double buffer are fixed by the files of this set (the superpixel's reciprocal
// table and the pixel's `swap` port are rendered for them); ROWS, COLS, the tile and the
// readout port may be overridden, and `tofprobe cosim --rtl` re-verifies an edited set.
module {{ name }} #(
    parameter integer ROWS = {{ rows }},
    parameter integer COLS = {{ cols }},
    parameter integer TILE_ROW0 = {{ tile_row0 }},
    parameter integer TILE_COL0 = {{ tile_col0 }},
    parameter integer TILE_ROWS = {{ trows }},
    parameter integer TILE_COLS = {{ tcols }},
    parameter integer READOUT_BITS = {{ b }},
    parameter integer BEAT_CYCLES = {{ g }},
    // Derived (not to be overridden): SPADs per pixel, inputs on the ports.
    parameter integer SPADS = {{ sp * sp }},
    parameter integer INPUTS = TILE_ROWS * TILE_COLS * SPADS
) (
    input  wire clk,
    input  wire rst,
    input  wire [INPUTS - 1:0] valid,
    input  wire [INPUTS * {{ t }} - 1:0] tdc,
    output wire pulse_o,
    output wire ready,
    output reg  ro_valid,
    output reg  [READOUT_BITS - 1:0] ro_data
);
{%- if sp > 1 %}
    localparam integer G = {{ sp }};
{%- endif %}
    localparam integer T = {{ t }};
    localparam integer W = {{ w }};
    localparam integer R = {{ r }};
    localparam integer IB = {{ ib }};
    localparam integer PIXELS = ROWS * COLS;
    localparam integer K = (W + READOUT_BITS - 1) / READOUT_BITS;
    localparam integer KB = K * READOUT_BITS;
    localparam integer SLOT = (R + 1) * K * BEAT_CYCLES;
    localparam integer RW = (ROWS > 2) ? $clog2(ROWS) : 1;
    localparam integer CW = (COLS > 2) ? $clog2(COLS) : 1;
    localparam integer QW = (PIXELS + 1 > 2) ? $clog2(PIXELS + 1) : 1;
    localparam integer KW = (K > 2) ? $clog2(K) : 1;
    localparam integer GW = (BEAT_CYCLES > 2) ? $clog2(BEAT_CYCLES) : 1;
    localparam integer SW = (SLOT > 2) ? $clog2(SLOT) : 1;
    // The sequencer's hold (double-buffered): the walk beyond the frame's N·C + 1 cycles, in
    // 64 bits, and the width of its counter (the least that holds WAIT).
    localparam [63:0] WALK = 64'd0 + PIXELS * 64'd1 * SLOT + 64'd1;
    localparam [63:0] ACC = 64'd{{ acc }};
    localparam [63:0] WAIT = ({% if dbuf %}1{% else %}0{% endif %} != 0 && WALK > ACC + 64'd1) ? WALK - ACC - 64'd1 : 64'd0;
    localparam integer HW = (WAIT + 64'd1 > 64'd2) ? $clog2(WAIT + 64'd1) : 1;
    localparam integer K_LAST = K - 1;
    localparam integer G_LAST = BEAT_CYCLES - 1;
    localparam [IB - 1:0] LAST_WORD = R[IB - 1:0];
    localparam [KW - 1:0] DM_END = K_LAST[KW - 1:0];
    localparam [GW - 1:0] DG_END = G_LAST[GW - 1:0];

    // ---- the sequencer (root) and the probe ROM ----
    wire s_pulse;
    wire s_ro;
    /* verilator lint_off UNUSEDSIGNAL */
    wire s_swap;
    wire [QW - 1:0] s_q;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [RW - 1:0] q_row;
    wire [CW - 1:0] q_col;
{%- if fourier %}
    wire [{{ aw - 1 }}:0] addr;
    wire [R - 1:0] rom_word;
    {{ rom_name }} u_rom (.addr(addr), .word(rom_word));
{%- endif %}
    {{ seq_name }} #(
        .PIXELS(PIXELS),
        .COLS(COLS),
        .SLOT(SLOT),
        .DOUBLE_BUFFER({% if dbuf %}1{% else %}0{% endif %}),
        .QW(QW),
        .RW(RW),
        .CW(CW),
        .SW(SW),
        .HW(HW),
        .WAIT(WAIT)
    ) u_sequencer (
        .clk(clk),
        .rst(rst),
        .pulse(s_pulse),
        .readout(s_ro),
        .swap(s_swap),
        .q(s_q),
        .row(q_row),
        .col(q_col){% if fourier %},
        .addr(addr){% endif %}
    );
{%- if mutation == "order_swap" %}
    // DELIBERATELY BROKEN: the readout order swaps its first two pixels.
    localparam [RW - 1:0] SWAP_R0 = 0;
    localparam [CW - 1:0] SWAP_C0 = 0;
    localparam [RW - 1:0] SWAP_R1 = (COLS > 1) ? 0 : 1;
    localparam [CW - 1:0] SWAP_C1 = (COLS > 1) ? 1 : 0;
    wire [RW - 1:0] s_row = (s_q == {QW{1'b0}}) ? SWAP_R1 : (s_q == { {(QW - 1){1'b0}}, 1'b1 }) ? SWAP_R0 : q_row;
    wire [CW - 1:0] s_col = (s_q == {QW{1'b0}}) ? SWAP_C1 : (s_q == { {(QW - 1){1'b0}}, 1'b1 }) ? SWAP_C0 : q_col;
{%- else %}
    wire [RW - 1:0] s_row = q_row;
    wire [CW - 1:0] s_col = q_col;
{%- endif %}

    // ---- broadcast stage 1: the root's registers ----
    reg b_pulse;
    reg b_ro;
{%- if dbuf %}
    reg b_swap;
{%- endif %}
    reg [RW - 1:0] b_row;
    reg [CW - 1:0] b_col;
{%- if fourier %}
    reg [R - 1:0] b_word;
{%- endif %}
    always @(posedge clk) begin
        if (rst) begin
            b_pulse <= 1'b0;
            b_ro <= 1'b0;
{%- if dbuf %}
            b_swap <= 1'b0;
{%- endif %}
            b_row <= {RW{1'b0}};
            b_col <= {CW{1'b0}};
{%- if fourier %}
            b_word <= {R{1'b0}};
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
{%- if mutation == "swap_late" %}
    // DELIBERATELY BROKEN: the swap passes one extra register (the shadow a cycle late).
    reg late_swap;
    always @(posedge clk) begin
        if (rst) late_swap <= 1'b0;
        else late_swap <= b_swap;
    end
{%- endif %}

    // ---- broadcast stage 2: one register per row (and the TDCs' strobe) ----
    // Each row's stage is its own register (`keep`): the rows' stages take the same value,
    // and a synthesis tool merges equal registers unless told not to — into one register
    // driving every pixel, the fan-out the stages are there to split.
    (* keep *) reg o_pulse;
    assign pulse_o = o_pulse;
    always @(posedge clk) begin
        if (rst) o_pulse <= 1'b0;
        else o_pulse <= b_pulse;
    end
    wire [TILE_ROWS - 1:0] r_pulse;
    wire [TILE_ROWS - 1:0] r_ro;
{%- if dbuf %}
    wire [TILE_ROWS - 1:0] r_swap;
{%- endif %}
    wire [TILE_ROWS * CW - 1:0] r_col;
{%- if fourier %}
    wire [TILE_ROWS * R - 1:0] r_word;
{%- endif %}
    genvar lr;
    genvar lc;
    generate
        for (lr = 0; lr < TILE_ROWS; lr = lr + 1) begin : g_row
            localparam integer ROW_I = TILE_ROW0 + lr;
            localparam [RW - 1:0] ROW = ROW_I[RW - 1:0];
            (* keep *) reg pulse_q;
            (* keep *) reg ro_q;
{%- if dbuf %}
            (* keep *) reg swap_q;
            assign r_swap[lr] = swap_q;
{%- endif %}
            (* keep *) reg [CW - 1:0] col_q;
            assign r_pulse[lr] = pulse_q;
            assign r_ro[lr] = ro_q;
            assign r_col[lr * CW +: CW] = col_q;
{%- if fourier %}
            (* keep *) reg [R - 1:0] word_q;
            assign r_word[lr * R +: R] = word_q;
{%- endif %}
{%- if mutation == "row_late" %}
            // DELIBERATELY BROKEN: row {{ fault_row }}'s broadcast passes one extra register.
            reg late_pulse;
{%- if fourier %}
            reg [R - 1:0] late_word;
{%- endif %}
            always @(posedge clk) begin
                if (rst) begin
                    late_pulse <= 1'b0;
{%- if fourier %}
                    late_word <= {R{1'b0}};
{%- endif %}
                end else begin
                    late_pulse <= b_pulse;
{%- if fourier %}
                    late_word <= b_word;
{%- endif %}
                end
            end
            wire late = (TILE_ROW0 + lr == {{ fault_row }});
            wire next_pulse = late ? late_pulse : b_pulse;
{%- if fourier %}
            wire [R - 1:0] next_word = late ? late_word : b_word;
{%- endif %}
{%- else %}
            wire next_pulse = b_pulse;
{%- if fourier %}
            wire [R - 1:0] next_word = b_word;
{%- endif %}
{%- endif %}
            // `keep` on the block too: yosys merges equal flops whose wires alone are kept.
            (* keep *) always @(posedge clk) begin
                if (rst) begin
                    pulse_q <= 1'b0;
                    ro_q <= 1'b0;
{%- if dbuf %}
                    swap_q <= 1'b0;
{%- endif %}
                    col_q <= {CW{1'b0}};
{%- if fourier %}
                    word_q <= {R{1'b0}};
{%- endif %}
                end else begin
                    pulse_q <= next_pulse;
                    ro_q <= b_ro && (b_row == ROW);
{%- if mutation == "swap_late" %}
                    swap_q <= late_swap;
{%- else if dbuf %}
                    swap_q <= b_swap;
{%- endif %}
                    col_q <= b_col;
{%- if fourier %}
                    word_q <= next_word;
{%- endif %}
                end
            end
        end
    endgenerate

    // ---- the pixels: each in its own generate block, with its inputs ({% if sp > 1 %}its G x G SPADs
    // averaged{% else %}its port bit and field{% endif %}) and its outputs as wires of the block (no array-wide vector) ----
    // `ready` is the AND of the rows' ANDs: one AND over every pixel would be a single
    // R x C-input expression, which Verilator folds in time cubic in its inputs (a
    // 64 x 64 lint: 213 CPU-s with the pixel a stub, against 18 s row by row).
    wire [TILE_ROWS - 1:0] row_ready;
    assign ready = &row_ready;
{%- if let Some(nb) = neighbour %}
    // DELIBERATELY BROKEN: the tile's pixel {{ nb }} reads the next pixel's TDC and that one its.
    localparam integer NB = {{ nb }};
    localparam integer TILE_PIXELS = TILE_ROWS * TILE_COLS;
{%- endif %}
    generate
        for (lr = 0; lr < TILE_ROWS; lr = lr + 1) begin : g_r
            wire [TILE_COLS - 1:0] ready_c;
            assign row_ready[lr] = &ready_c;
            for (lc = 0; lc < TILE_COLS; lc = lc + 1) begin : g_c
{%- if sp == 1 || neighbour.is_some() %}
                localparam integer I = lr * TILE_COLS + lc;
{%- endif %}
                localparam integer COL_I = TILE_COL0 + lc;
                localparam [CW - 1:0] COL = COL_I[CW - 1:0];
                wire v_in;
                wire [T - 1:0] t_in;
{%- if sp > 1 %}
                wire [SPADS - 1:0] spad_valid;
                wire [SPADS * T - 1:0] spad_tdc;
                genvar s;
                for (s = 0; s < SPADS; s = s + 1) begin : g_spad
                    // SPAD s of the superpixel (row-major): (lr*G + s/G, lc*G + s%G) of the grid.
                    localparam integer BIT = (lr * G + s / G) * (TILE_COLS * G) + lc * G + s % G;
                    assign spad_valid[s] = valid[BIT];
                    assign spad_tdc[s * T +: T] = tdc[BIT * T +: T];
                end
                {{ sp_name }} u_superpixel (
                    .spad_valid(spad_valid),
                    .spad_tdc(spad_tdc),
                    .valid(v_in),
                    .tdc(t_in)
                );
{%- else %}
                assign v_in = valid[I];
                assign t_in = tdc[I * T +: T];
{%- endif %}
{%- if neighbour.is_some() %}
                localparam integer SRC = (I == NB) ? (I + 1) % TILE_PIXELS
                    : ((NB + 1) % TILE_PIXELS == I) ? NB : I;
                wire [T - 1:0] t_src;
                if (SRC == I) begin : g_own
                    assign t_src = t_in;
                end else begin : g_crossed
                    assign t_src = g_r[SRC / TILE_COLS].g_c[SRC % TILE_COLS].t_in;
                end
{%- endif %}
                wire rd_valid;
                wire [IB - 1:0] rd_index;
                wire [W - 1:0] rd_data;
                {{ pixel_name }} u_pixel (
                    .clk(clk),
                    .rst(rst),
                    .pulse(r_pulse[lr]),
                    .valid(v_in),
                    .tdc({% if neighbour.is_some() %}t_src{% else %}t_in{% endif %}),
{%- if fourier %}
                    .rom_word(r_word[lr * R +: R]),
{%- endif %}
                    .readout(r_ro[lr] && (r_col[lr * CW +: CW] == COL)),
{%- if dbuf %}
                    .swap(r_swap[lr]),
{%- endif %}
                    .ready(ready_c[lc]),
                    .rd_valid(rd_valid),
                    .rd_index(rd_index),
                    .rd_data(rd_data)
                );
            end
        end
    endgenerate

    // ---- the read select: a row onto the column buses, a column onto the capture ----
    // The strobe's root registers, two more stages on: the select changes the cycle after
    // the pixel takes its strobe, when its first word is still a cycle away.
    reg d_ro;
    reg [RW - 1:0] d_row;
    reg [CW - 1:0] d_col;
    reg e_ro;
    reg [RW - 1:0] e_row;
    reg [CW - 1:0] e_col;
    reg [TILE_ROWS - 1:0] m_row;
    reg [CW - 1:0] m_col;
    always @(posedge clk) begin
        if (rst) begin
            d_ro <= 1'b0;
            d_row <= {RW{1'b0}};
            d_col <= {CW{1'b0}};
            e_ro <= 1'b0;
            e_row <= {RW{1'b0}};
            e_col <= {CW{1'b0}};
            m_col <= {CW{1'b0}};
        end else begin
            d_ro <= b_ro;
            d_row <= b_row;
            d_col <= b_col;
            e_ro <= d_ro;
            e_row <= d_row;
            e_col <= d_col;
            if (e_ro) m_col <= e_col;
        end
    end
    generate
        for (lr = 0; lr < TILE_ROWS; lr = lr + 1) begin : g_sel
            localparam integer ROW_I = TILE_ROW0 + lr;
            localparam [RW - 1:0] ROW = ROW_I[RW - 1:0];
            always @(posedge clk) begin
                if (rst) m_row[lr] <= 1'b0;
{%- if mutation == "row_stuck" %}
                // DELIBERATELY BROKEN: row {{ fault_row }} never leaves readout once selected.
                else if (e_ro) m_row[lr] <= (e_row == ROW) || ((TILE_ROW0 + lr == {{ fault_row }}) && m_row[lr]);
{%- else %}
                else if (e_ro) m_row[lr] <= (e_row == ROW);
{%- endif %}
            end
        end
    endgenerate
    // Column buses: the OR of the selected rows' pixels, a chain down each column (one
    // stage of wires per row: no signal feeds itself).
    wire [TILE_COLS - 1:0] bus_valid;
    wire [TILE_COLS * IB - 1:0] bus_index;
    wire [TILE_COLS * W - 1:0] bus_data;
    generate
        for (lc = 0; lc < TILE_COLS; lc = lc + 1) begin : g_bus
            for (lr = 0; lr < TILE_ROWS; lr = lr + 1) begin : g_t
                wire v_px = m_row[lr] & g_r[lr].g_c[lc].rd_valid;
                wire [IB - 1:0] x_px = {IB{m_row[lr]}} & g_r[lr].g_c[lc].rd_index;
                wire [W - 1:0] d_px = {W{m_row[lr]}} & g_r[lr].g_c[lc].rd_data;
                wire v;
                wire [IB - 1:0] x;
                wire [W - 1:0] d;
                if (lr == 0) begin : g_first
                    assign v = v_px;
                    assign x = x_px;
                    assign d = d_px;
                end else begin : g_next
                    assign v = g_t[lr - 1].v | v_px;
                    assign x = g_t[lr - 1].x | x_px;
                    assign d = g_t[lr - 1].d | d_px;
                end
            end
            assign bus_valid[lc] = g_t[TILE_ROWS - 1].v;
            assign bus_index[lc * IB +: IB] = g_t[TILE_ROWS - 1].x;
            assign bus_data[lc * W +: W] = g_t[TILE_ROWS - 1].d;
        end
    endgenerate
    // The selected column of the tile (none: an absent pixel's slot carries no beat): its
    // offset from the tile's first column, wrapped past the tile's width when left of it.
    localparam [CW:0] TC0 = TILE_COL0[CW:0];
    localparam [CW:0] TCOLS = TILE_COLS[CW:0];
    wire [CW:0] m_off = {1'b0, m_col} - TC0;
    wire m_in_tile = m_off < TCOLS;
    wire [CW - 1:0] m_lc = m_off[CW - 1:0];
    reg m_valid;
    reg [IB - 1:0] m_index;
    reg [W - 1:0] m_data;
    integer j;
    always @* begin
        m_valid = 1'b0;
        m_index = {IB{1'b0}};
        m_data = {W{1'b0}};
        for (j = 0; j < TILE_COLS; j = j + 1) begin
            if (m_in_tile && m_lc == j[CW - 1:0]) begin
                m_valid = bus_valid[j];
                m_index = bus_index[j * IB +: IB];
                m_data = bus_data[j * W +: W];
            end
        end
    end

    // ---- the readout buffer and the port ----
{%- for j in words %}
    reg [W - 1:0] rbuf_{{ j }};
{%- endfor %}
    reg dr_act;
    reg [IB - 1:0] dj;
    reg [KW - 1:0] dm;
    reg [GW - 1:0] dg;
    wire beat = dr_act && (BEAT_CYCLES == 1 || dg == {GW{1'b0}});
    wire step = dr_act && (BEAT_CYCLES == 1 || dg == DG_END);
    wire last = (dj == LAST_WORD) && (K == 1 || dm == DM_END);
    reg [W - 1:0] dw;
    always @* begin
        case (dj)
{%- for j in words %}
            {{ ib }}'d{{ j }}: dw = rbuf_{{ j }};
{%- endfor %}
            default: dw = {W{1'b0}};
        endcase
    end
    // Registers sign-extended, the status word (index R) zero-extended, to K x READOUT_BITS bits.
    wire dsx = dw[W - 1] && (dj != LAST_WORD);
    wire [KB - 1:0] dx;
    generate
        if (KB > W) begin : g_ext
            assign dx = { {(KB - W){dsx}}, dw };
        end else begin : g_noext
            assign dx = dw;
            /* verilator lint_off UNUSEDSIGNAL */
            wire unused_dsx = dsx;
            /* verilator lint_on UNUSEDSIGNAL */
        end
    endgenerate
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
            dj <= {IB{1'b0}};
            dm <= {KW{1'b0}};
            dg <= {GW{1'b0}};
            ro_valid <= 1'b0;
            ro_data <= {READOUT_BITS{1'b0}};
        end else begin
            ro_valid <= beat;
            if (beat) ro_data <= dx[dm * READOUT_BITS +: READOUT_BITS];
            if (m_valid && (m_index == {IB{1'b0}})) begin
                // A pixel's word 0 is in the buffer: its drain starts at the next edge.
                dr_act <= 1'b1;
                dj <= {IB{1'b0}};
                dm <= {KW{1'b0}};
                dg <= {GW{1'b0}};
            end else if (dr_act) begin
                if (BEAT_CYCLES > 1) dg <= step ? {GW{1'b0}} : dg + 1'b1;
                if (step) begin
                    if (last) begin
                        dr_act <= 1'b0;
                    end else if (K == 1 || dm == DM_END) begin
                        dm <= {KW{1'b0}};
                        dj <= dj + 1'b1;
                    end else begin
                        dm <= dm + 1'b1;
                    end
                end
            end
        end
    end
endmodule

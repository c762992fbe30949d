{{ header }}
// The chip-level probe ROM: {{ l }} words of {{ r }} bits (bit r of a word: 1 = register r
// adds). {% if table %}Rendered as a case table (small depth: synthesises to logic).{% else %}Loaded from {{ hex_file }} with $readmemh (run the simulator from this directory).{% endif %}
module {{ name }} (
    input  wire [{{ aw - 1 }}:0] addr,
    output reg  [{{ r - 1 }}:0] word
);
{%- if table %}
    always @* begin
        case (addr)
{%- for e in entries %}
            {{ aw }}'d{{ e.0 }}: word = {{ r }}'h{{ e.1 }};
{%- endfor %}
            default: word = {{ r }}'d0;
        endcase
    end
{%- else %}
    reg [{{ r - 1 }}:0] mem [0:{{ l - 1 }}];
    initial $readmemh("{{ hex_file }}", mem);
    always @* word = mem[addr];
{%- endif %}
endmodule

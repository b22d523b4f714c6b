// tmds_encoder — one DVI 1.0 TMDS channel (section 3.3.3 of the DVI specification): 8 data
// bits to 10 with transition minimisation and DC balance while `de`; one of the four control
// symbols (c1, c0) in blanking, which resets the running disparity. Output registered.

`default_nettype none

module tmds_encoder (
    input wire clk,
    input wire [7:0] d,
    input wire de,
    input wire c0,
    input wire c1,
    output reg [9:0] q
);

// Ones in the data byte, and in the 8 transition-minimised bits.
function [3:0] ones8;
    input [7:0] v;
    integer b;
    begin
        ones8 = 4'd0;
        for (b = 0; b < 8; b = b + 1) ones8 = ones8 + {3'd0, v[b]};
    end
endfunction

wire [3:0] n1d = ones8(d);
wire use_xnor = (n1d > 4'd4) || (n1d == 4'd4 && !d[0]);
// Transition minimisation: each bit the XOR (or XNOR) of the data bit and the bit before it.
function [8:0] minimise;
    input [7:0] v;
    input xnor_mode;
    integer b;
    begin
        minimise[0] = v[0];
        for (b = 1; b < 8; b = b + 1) minimise[b] = xnor_mode ? ~(minimise[b-1] ^ v[b]) : (minimise[b-1] ^ v[b]);
        minimise[8] = !xnor_mode;
    end
endfunction
wire [8:0] qm = minimise(d, use_xnor);

// Disparity in ones minus zeros, as a signed count of bits (range -10..10 at most).
wire signed [5:0] n1q = {2'b00, ones8(qm[7:0])};
wire signed [5:0] diff = n1q + n1q - 6'sd8;   // ones - zeros of qm[7:0]
reg signed [5:0] cnt;
reg signed [5:0] cnt_next;
reg [9:0] q_next;

always @(*) begin
    if (!de) begin
        cnt_next = 6'sd0;
        case ({c1, c0})
            2'b00: q_next = 10'b1101010100;
            2'b01: q_next = 10'b0010101011;
            2'b10: q_next = 10'b0101010100;
            default: q_next = 10'b1010101011;
        endcase
    end else if (cnt == 6'sd0 || diff == 6'sd0) begin
        q_next = {~qm[8], qm[8], qm[8] ? qm[7:0] : ~qm[7:0]};
        cnt_next = qm[8] ? cnt + diff : cnt - diff;
    end else if ((cnt > 6'sd0 && diff > 6'sd0) || (cnt < 6'sd0 && diff < 6'sd0)) begin
        q_next = {1'b1, qm[8], ~qm[7:0]};
        cnt_next = cnt - diff + (qm[8] ? 6'sd2 : 6'sd0);
    end else begin
        q_next = {1'b0, qm[8], qm[7:0]};
        cnt_next = cnt + diff - (qm[8] ? 6'sd0 : 6'sd2);
    end
end

always @(posedge clk) begin
    q <= q_next;
    cnt <= cnt_next;
end

endmodule

`default_nettype wire

// The simple routing between a DynRTC's per-type caches and the memory controller's cache port
// (paper section 3: "acts like a multiplexer for memory requests and uses a labeled broadcast for
// memory responses"; memif/routing.h, D23), in the cycle model's order of a cycle:
//   broadcast: the port's oldest response goes to the client its label names, into that client's
//              fill queue, if the queue has room; else it waits at the head (a shared bus);
//   arbitrate: one line request a cycle, round-robin among the clients with one: the scan starts
//              at `rr`, the first client whose memory queue holds a request is taken (mem_take)
//              if the port's request channel has room (!port_blocked), and rr moves past it.
// The port's response channel (capacity RESP_CAP, latency 1: a response the controller pushes in
// cycle c is seen in c + 1) is this module's FIFO; the controller pushes only while it has room,
// so `overflow` rises only when the RTL has left the model's track. One response a cycle: the
// routing's broadcast width (memif responses_per_cycle) of 1.
// Clients are numbered by their controller client ids (cfg_id): a response's label is an id.
module routing #(
    parameter int CLIENTS  = 3,
    parameter int RESP_CAP = 4,   // the controller port's response channel (a power of two)
    parameter int TAG_W    = 4,   // response tag bits (a cache's MSHR)
    parameter int WORDS    = 4,   // memif kMaxRequestWords
    parameter int CW       = CLIENTS > 1 ? $clog2(CLIENTS) : 1
) (
    input  logic                    clk,
    input  logic                    rst,
    input  logic [CLIENTS*16-1:0]   cfg_id,        // client i's controller id at [16*i +: 16]
    // Requests: each client's memory queue holds one (its head), the routing takes it.
    input  logic [CLIENTS-1:0]      mq_valid,
    output logic [CLIENTS-1:0]      mem_take,
    input  logic                    port_blocked,  // the port's request channel is full
    output logic                    fwd_valid,     // a request forwarded this cycle
    output logic [CW-1:0]           fwd_client,
    // Responses: pushed by the controller into the port's channel this cycle.
    input  logic                    rsp_valid,
    input  logic [15:0]             rsp_client,
    input  logic [TAG_W-1:0]        rsp_tag,
    input  logic [WORDS*32-1:0]     rsp_words,
    // Fills: one client's fill queue is pushed this cycle.
    input  logic [CLIENTS-1:0]      fill_ready,
    output logic [CLIENTS-1:0]      fill_valid,
    output logic [TAG_W-1:0]        fill_tag,
    output logic [WORDS*32-1:0]     fill_words,
    output logic                    overflow,
    output logic                    unknown_client  // a response labelled for no client of ours
);
  localparam int QW = RESP_CAP > 1 ? $clog2(RESP_CAP) : 1;

  logic [15:0]         q_client[RESP_CAP];
  logic [TAG_W-1:0]    q_tag[RESP_CAP];
  logic [WORDS*32-1:0] q_words[RESP_CAP];
  logic [QW-1:0]       q_head;
  logic [QW:0]         q_count;
  logic [CW-1:0]       rr;

  // ---- broadcast: the head's client, and whether its fill queue has room ----------------------
  logic          head_known;
  logic [CW-1:0] head_client;
  always_comb begin
    head_known = 1'b0;
    head_client = '0;
    for (int i = 0; i < CLIENTS; i++)
      if (cfg_id[16*i+:16] == q_client[q_head]) begin
        head_known = 1'b1;
        head_client = CW'(i);
      end
  end
  logic deliver;
  assign deliver = q_count != '0 && head_known && fill_ready[head_client];
  always_comb begin
    fill_valid = '0;
    if (deliver) fill_valid[head_client] = 1'b1;
  end
  assign fill_tag = q_tag[q_head];
  assign fill_words = q_words[q_head];
  assign unknown_client = q_count != '0 && !head_known;

  // ---- arbitrate: the first client from rr with a request ----------------------------------------
  logic          any;
  logic [CW-1:0] pick;
  always_comb begin
    any = 1'b0;
    pick = '0;
    for (int k = CLIENTS - 1; k >= 0; k--) begin
      logic [CW:0] c;  // rr + k < 2 CLIENTS: one subtraction wraps it
      c = {1'b0, rr} + (CW + 1)'(k);
      if (c >= (CW + 1)'(CLIENTS)) c = c - (CW + 1)'(CLIENTS);
      if (mq_valid[c[CW-1:0]]) begin
        any = 1'b1;
        pick = c[CW-1:0];
      end
    end
  end
  assign fwd_valid = any && !port_blocked;
  assign fwd_client = pick;
  always_comb begin
    mem_take = '0;
    if (fwd_valid) mem_take[pick] = 1'b1;
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      q_head <= '0;
      q_count <= '0;
      rr <= '0;
      overflow <= 1'b0;
    end else begin
      if (rsp_valid) begin
        q_client[QW'((QW + 1)'(q_head) + q_count)] <= rsp_client;
        q_tag[QW'((QW + 1)'(q_head) + q_count)] <= rsp_tag;
        q_words[QW'((QW + 1)'(q_head) + q_count)] <= rsp_words;
        if (q_count == (QW + 1)'(RESP_CAP) && !deliver) overflow <= 1'b1;
      end
      if (deliver) q_head <= q_head + 1'b1;  // (RESP_CAP a power of two)
      q_count <= q_count + (QW + 1)'(rsp_valid) - (QW + 1)'(deliver);
      if (fwd_valid) rr <= pick == CW'(CLIENTS - 1) ? '0 : pick + 1'b1;
    end
  end
endmodule

// The mailboxed list unit of a DynRTP (paper section 3.1, Figure 2 paths c and d; units/list_step.h,
// units/list_unit.cpp; D28), computing on its own: the thread machinery of rtl/unit_threads.sv
// around the list step.
//   Per thread: its level (0 top, 1 bottom) and per level the list cursor (next, end) and the
//   rays still in the list; the entry word its last cache response brought; the object mailbox
//   (MB entries, top-level lists) and the triangle mailbox (TMB entries, bottom-level lists).
//   Arrival (units/boundary_list.h): a leaf's list starts (op 1: next, end, mask), or the level's
//   list resumes with the rays still in it (op 0: the intersection unit's any-hit terminations
//   removed some). The entry at `next` is fetched through the list cache at accept; a resume
//   whose list is done (an object's bottom level ended after the top-level list's last entry)
//   fetches nothing and leaves with kind 2 (D49).
//   Step (one cycle, at issue): the entry goes through the level's mailbox; if a ray still needs
//   it, it goes to the transformation unit (kind 0, path d) with those rays, and a top-level
//   entry (an object the thread enters) clears the triangle mailbox; otherwise the list goes on
//   through the unit's own loop (kind 1) or, at its end, the traversal unit pops (kind 2). An
//   entry carries on what the units after it need to route the thread (D49): the level's rays
//   still in the list and whether the entry was its last (the cursor after it at the end),
//   which travel with it through the transformation unit to the intersection unit (paths d, e).
//   Side band (path a): a new packet clears the thread's object mailbox (D28).
// The output leaves DEPTH cycles after the issue (the mailbox compare, lat_cmp).
module list_unit #(
    parameter int THREADS = 16,
    parameter int P       = 4,
    parameter int MB      = 8,
    parameter int TMB     = 8,
    parameter int DEPTH   = 1,
    parameter bit FAULT_MAILBOX_NEVER_HITS = 1'b0,
    parameter bit FAULT_PRIORITY_SWAP = 1'b0,  // the loop and the intersection path swapped
    parameter int TW      = THREADS > 1 ? $clog2(THREADS) : 1
) (
    input  logic                 clk,
    input  logic                 rst,
    // Input paths in the model's priority (units/dynrtp.cpp): 0 the unit's loop, 1 from the
    // intersection unit, 2 from the traversal unit (path c). Path i's fields are the i-th slices
    // of the flat vectors (in_thread[i*TW +: TW], in_next[i*32 +: 32], ...): yosys 0.23 reads no
    // packed arrays.
    input  logic [2:0]           in_valid,
    input  logic [3*TW-1:0]      in_thread,
    input  logic [2:0]           in_start,
    input  logic [2:0]           in_level,
    input  logic [3*32-1:0]      in_next,
    input  logic [3*32-1:0]      in_end,
    input  logic [3*P-1:0]       in_mask,
    // Side band: packet starts (two per cycle: the RGS admits one and hands on another).
    input  logic [1:0]           clr_valid,
    input  logic [2*TW-1:0]      clr_thread,
    // List cache.
    output logic                 req_valid,
    output logic [31:0]          req_item,
    output logic [TW-1:0]        req_thread,
    input  logic                 req_ready,
    input  logic                 resp_valid,
    input  logic [TW-1:0]        resp_thread,
    input  logic [31:0]          resp_word,
    // Output.
    output logic                 out_valid,
    output logic [TW-1:0]        out_thread,
    output logic [1:0]           out_kind,
    output logic                 out_level,
    output logic [31:0]          out_next,
    output logic [31:0]          out_entry,
    output logic [P-1:0]         out_mask,
    output logic [P-1:0]         out_list,  // kind 0: the level's rays still in the list, else 0
    output logic                 out_last   // kind 0: the entry was the list's last, else 0
);
  localparam int PW = 2 + 1 + 32 + 32 + P + P + 1;
  localparam int MBN = MB > 0 ? MB : 1;
  localparam int TMBN = TMB > 0 ? TMB : 1;
  localparam int MBB = MB > 1 ? $clog2(MB + 1) : 1;
  localparam int TMBB = TMB > 1 ? $clog2(TMB + 1) : 1;
  localparam int MSB = MB > 1 ? $clog2(MB) : 1;  // slot bits
  localparam int TMSB = TMB > 1 ? $clog2(TMB) : 1;

  // ---- per-thread state ------------------------------------------------------------------------
  logic          level[THREADS];
  logic [31:0]   cur_next[THREADS][2];
  logic [31:0]   cur_end[THREADS][2];
  logic [P-1:0]  cur_mask[THREADS][2];
  logic [31:0]   word[THREADS];
  logic [31:0]   ob_id[THREADS][MBN];
  logic [P-1:0]  ob_mask[THREADS][MBN];
  logic [MSB-1:0] ob_head[THREADS];
  logic [MBB-1:0] ob_size[THREADS];
  logic [31:0]   tr_id[THREADS][TMBN];
  logic [P-1:0]  tr_mask[THREADS][TMBN];
  logic [TMSB-1:0] tr_head[THREADS];
  logic [TMBB-1:0] tr_size[THREADS];

  // ---- the thread machinery --------------------------------------------------------------------
  logic acc_valid, iss_valid;
  logic [TW-1:0] acc_thread, iss_thread;
  logic [PW-1:0] iss_payload, out_payload;
  // A thread back from an object whose top-level list is done (or whose rays are) reads nothing:
  // it passes through the issue slot on to the traversal unit's pop (D49).
  logic acc_done;
  logic acc_lv;
  assign acc_lv = level[acc_thread];
  assign acc_done = cur_next[acc_thread][acc_lv] >= cur_end[acc_thread][acc_lv] ||
                    cur_mask[acc_thread][acc_lv] == '0;
  unit_threads #(
      .THREADS(THREADS), .INPUTS(3), .DEPTH(DEPTH), .PW(PW), .IW(32), .CW(1), .SW(1),
      .FAULT_PRIORITY_SWAP(FAULT_PRIORITY_SWAP)
  ) threads (
      .clk, .rst, .in_valid, .in_thread,
      .acc_valid, .acc_thread,
      .acc_first(cur_next[acc_thread][level[acc_thread]]), .acc_count(~acc_done),
      .req_valid, .req_item, .req_thread, .req_ready, .resp_valid, .resp_thread,
      .iss_valid, .iss_thread, .iss_steps(1'b1), .iss_chain(1'b0), .iss_payload,
      .out_valid, .out_thread, .out_payload, .out_ready(1'b1));
  /* verilator lint_off UNUSEDSIGNAL */
  logic unused_acc;
  assign unused_acc = acc_valid;
  /* verilator lint_on UNUSEDSIGNAL */
  assign {out_kind, out_level, out_next, out_entry, out_mask, out_list, out_last} = out_payload;

  // ---- the list step of the issuing thread -----------------------------------------------------
  logic          lv;
  logic [31:0]   nx, en, entry;
  logic [P-1:0]  m;
  assign lv = level[iss_thread];
  assign nx = cur_next[iss_thread][lv];
  assign en = cur_end[iss_thread][lv];
  assign m = cur_mask[iss_thread][lv];
  assign entry = word[iss_thread];

  // The issuing thread's mailboxes, slot k at [k*32 +: 32] and [k*P +: P].
  logic [MBN*32-1:0] ob_ids;
  logic [MBN*P-1:0] ob_masks;
  logic [TMBN*32-1:0] tr_ids;
  logic [TMBN*P-1:0] tr_masks;
  always_comb begin
    for (int k = 0; k < MBN; k++) begin
      ob_ids[k*32+:32] = ob_id[iss_thread][k];
      ob_masks[k*P+:P] = ob_mask[iss_thread][k];
    end
    for (int k = 0; k < TMBN; k++) begin
      tr_ids[k*32+:32] = tr_id[iss_thread][k];
      tr_masks[k*P+:P] = tr_mask[iss_thread][k];
    end
  end
  logic [P-1:0] ob_todo, ob_slot_mask, tr_todo, tr_slot_mask;
  logic [MSB-1:0] ob_slot, ob_next_head;
  logic [MBB-1:0] ob_next_size;
  logic [TMSB-1:0] tr_slot, tr_next_head;
  logic [TMBB-1:0] tr_next_size;
  logic ob_write, tr_write;
  list_mailbox #(.N(MB), .P(P), .FAULT_NEVER_HITS(FAULT_MAILBOX_NEVER_HITS)) objects (
      .ids(ob_ids), .masks(ob_masks), .head(ob_head[iss_thread]),
      .size(ob_size[iss_thread]), .id(entry), .mask(m), .todo(ob_todo), .slot(ob_slot),
      .slot_mask(ob_slot_mask), .next_head(ob_next_head), .next_size(ob_next_size),
      .write(ob_write));
  list_mailbox #(.N(TMB), .P(P), .FAULT_NEVER_HITS(FAULT_MAILBOX_NEVER_HITS)) triangles (
      .ids(tr_ids), .masks(tr_masks), .head(tr_head[iss_thread]),
      .size(tr_size[iss_thread]), .id(entry), .mask(m), .todo(tr_todo), .slot(tr_slot),
      .slot_mask(tr_slot_mask), .next_head(tr_next_head), .next_size(tr_next_size),
      .write(tr_write));

  logic [P-1:0] todo;
  logic [31:0] nx1;
  logic [1:0] kind;
  assign todo = lv ? tr_todo : ob_todo;
  assign nx1 = nx + 32'd1;
  logic fin;  // the list was done on arrival: no entry was read (D49)
  assign fin = nx >= en || m == '0;
  assign kind = fin ? 2'd2 : todo != '0 ? 2'd0 : (nx1 < en && m != '0) ? 2'd1 : 2'd2;
  logic handed;  // the entry goes to the transformation unit
  assign handed = kind == 2'd0;
  assign iss_payload = {kind, lv, fin ? nx : nx1, handed ? entry : 32'd0, handed ? todo : m,
                        handed ? m : {P{1'b0}}, handed && nx1 >= en};

  always_ff @(posedge clk) begin
    if (rst) begin
      for (int t = 0; t < THREADS; t++) begin
        level[t] <= 1'b0;
        ob_head[t] <= '0;
        ob_size[t] <= '0;
        tr_head[t] <= '0;
        tr_size[t] <= '0;
      end
    end else begin
      if (resp_valid) word[resp_thread] <= resp_word;
      if (iss_valid && !fin) begin
        cur_next[iss_thread][lv] <= nx1;
        if (!lv && ob_write) begin
          ob_id[iss_thread][ob_slot] <= entry;
          ob_mask[iss_thread][ob_slot] <= ob_slot_mask;
          ob_head[iss_thread] <= ob_next_head;
          ob_size[iss_thread] <= ob_next_size;
        end
        if (lv && tr_write) begin
          tr_id[iss_thread][tr_slot] <= entry;
          tr_mask[iss_thread][tr_slot] <= tr_slot_mask;
          tr_head[iss_thread] <= tr_next_head;
          tr_size[iss_thread] <= tr_next_size;
        end
        // The thread enters the object: its triangles start afresh (TransformationStep::object).
        if (!lv && kind == 2'd0) begin
          tr_head[iss_thread] <= '0;
          tr_size[iss_thread] <= '0;
        end
      end
      for (int c = 0; c < 2; c++)
        if (clr_valid[c]) begin
          ob_head[clr_thread[c*TW+:TW]] <= '0;
          ob_size[clr_thread[c*TW+:TW]] <= '0;
        end
      for (int i = 0; i < 3; i++)
        if (in_valid[i]) begin
          level[in_thread[i*TW+:TW]] <= in_level[i];
          cur_mask[in_thread[i*TW+:TW]][in_level[i]] <= in_mask[i*P+:P];
          if (in_start[i]) begin
            cur_next[in_thread[i*TW+:TW]][in_level[i]] <= in_next[i*32+:32];
            cur_end[in_thread[i*TW+:TW]][in_level[i]] <= in_end[i*32+:32];
          end
        end
    end
  end
endmodule

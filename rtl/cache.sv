// One per-type item cache of a DynRTP (paper section 3: "individual caches for each type of
// data"; Table 2; memif/cache.h, docs/memif.md, D20), in the cycle model's order of a cycle:
//   1. fill:    a fill that arrived (the routing pushed it in an earlier cycle) is written into its
//               line, if the line still waits for it, and its MSHR joins the filled FIFO;
//   2. deliver: the filled FIFO's front MSHR (the one just filled, if the FIFO was empty: bypass)
//               answers its oldest waiting request; the last one frees the MSHR;
//   3. lookup:  the request queue's head: a hit answers (if deliver left the response port free),
//               a request for an item whose fill is on its way joins that MSHR's targets (merge),
//               else a miss takes the lowest free MSHR, a victim line of the set (the first empty
//               way, else the least recently used) and sends one line request towards memory.
// The request queue (REQ_CAP entries), the memory request queue and the fill queue (MEM_CAP each)
// have the latency 1 of the model's channels: what is pushed in cycle c is seen in c + 1; a slot
// freed in c is free for a push in c + 1 (the ready signals are registers). A response leaves
// HIT_LAT - 1 cycles after its push (the response channel's latency): the unit takes one every
// cycle (units/cycle_unit.cpp receive), so that channel never fills and is a delay line here.
//
// Sizes: ITEMS lines of up to WORDS words, up to WAYS ways; the run's lines, ways and words are
// inputs (cfg_*: one build serves the prototype's 512-item caches, small and 2-way ones, and all
// three item types), fixed while the cache runs. Lines are set-major: line = set * ways + way.
// Storage: the data words in a memory with one write port (the fill) and a registered read port
// (the hit's line, read in the lookup's cycle and used one cycle later inside the response's
// delay line): block RAM. The item tags in a memory written only by a miss (one write port, one
// asynchronous read port per way). The valid and allocated bits and the LRU ranks are registers
// (reset, and written by the fill and the miss in one cycle).
module cache #(
    parameter int ITEMS    = 512,  // lines the arrays hold (a power of two)
    parameter int WAYS     = 2,    // the most ways a run may use (a power of two)
    parameter int WORDS    = 4,    // the widest item (memif kMaxRequestWords)
    parameter int HIT_LAT  = 2,    // cache.hit_latency (>= 2)
    parameter int MISSES   = 8,    // cache.misses: MSHRs
    parameter int TARGETS  = 16,   // cache.merge_targets: requests per MSHR, the first included
    parameter int REQ_CAP  = 4,    // cache.request_queue
    parameter int MEM_CAP  = 2,    // cache.memory_queue
    parameter int RW       = 3,    // label.requester bits (UNIT)
    parameter int TW       = 12,   // label.tag bits (TID)
    parameter bit FAULT_MERGE_WRONG = 1'b0,  // tests only: a merge joins the next MSHR
    parameter int LW       = ITEMS > 1 ? $clog2(ITEMS) : 1,
    parameter int MW       = MISSES > 1 ? $clog2(MISSES) : 1
) (
    input  logic                  clk,
    input  logic                  rst,
    // The run's configuration: log2 of its lines and ways, its item words, its region base
    // (memif/image_format.h MemoryImage::locate: item i at scene bank 3 + i mod 3, word
    // base + (i div 3) * words).
    input  logic [4:0]            cfg_lines_log2,
    input  logic [4:0]            cfg_ways_log2,
    input  logic [2:0]            cfg_words,
    input  logic [31:0]           cfg_base,
    // Unit -> cache: a request pushed this cycle (only while req_ready).
    input  logic                  req_valid,
    input  logic [31:0]           req_index,
    input  logic [RW-1:0]         req_requester,
    input  logic [TW-1:0]         req_tag,
    output logic                  req_ready,
    // The lookup: the request taken from the queue this cycle, hit (0), merge (1) or miss (2),
    // and the MSHR it joins or allocates.
    output logic                  acc_valid,
    output logic [31:0]           acc_index,
    output logic [RW-1:0]         acc_requester,
    output logic [TW-1:0]         acc_tag,
    output logic [1:0]            acc_kind,
    output logic [MW-1:0]         acc_mshr,
    // Cache -> unit: the response the unit takes this cycle (words w at resp_words[32*w +: 32]).
    output logic                  resp_valid,
    output logic [31:0]           resp_index,
    output logic [RW-1:0]         resp_requester,
    output logic [TW-1:0]         resp_tag,
    output logic [WORDS*32-1:0]   resp_words,
    // Cache -> routing: the line request pushed this cycle, and the queue's head, which the
    // routing takes (mem_take) when it forwards it.
    output logic                  mreq_valid,
    output logic [MW-1:0]         mreq_tag,
    output logic [2:0]            mreq_bank,
    output logic [31:0]           mreq_offset,
    output logic [2:0]            mreq_words,
    output logic                  mq_valid,
    output logic [MW-1:0]         mq_tag,
    output logic [2:0]            mq_bank,
    output logic [31:0]           mq_offset,
    input  logic                  mem_take,
    // Routing -> cache: a fill pushed this cycle (only while fill_ready), labelled with its MSHR.
    input  logic                  fill_valid,
    input  logic [MW-1:0]         fill_tag,
    input  logic [WORDS*32-1:0]   fill_words,
    output logic                  fill_ready
);
  localparam int WB = WAYS > 1 ? $clog2(WAYS) : 1;  // way and LRU rank bits
  localparam int DW = WORDS * 32;
  localparam int QW = REQ_CAP > 1 ? $clog2(REQ_CAP) : 1;
  localparam int FW = MEM_CAP > 1 ? $clog2(MEM_CAP) : 1;
  localparam int GW = TARGETS > 1 ? $clog2(TARGETS) : 1;

  // ---- the queues' registers -----------------------------------------------------------------
  logic [31:0] rq_index[REQ_CAP];
  logic [RW-1:0] rq_requester[REQ_CAP];
  logic [TW-1:0] rq_tag[REQ_CAP];
  logic [QW-1:0] rq_head;
  logic [QW:0] rq_count;
  logic [MW-1:0] fq_tag[MEM_CAP];
  logic [DW-1:0] fq_words[MEM_CAP];
  logic [FW-1:0] fq_head;
  logic [FW:0] fq_count;
  logic [MW-1:0] mq_tag_r[MEM_CAP];
  logic [2:0] mq_bank_r[MEM_CAP];
  logic [31:0] mq_offset_r[MEM_CAP];
  logic [FW-1:0] mq_head;
  logic [FW:0] mq_count;
  assign req_ready = rq_count < (QW + 1)'(REQ_CAP);
  assign fill_ready = fq_count < (FW + 1)'(MEM_CAP);
  assign mq_valid = mq_count != '0;
  assign mq_tag = mq_tag_r[mq_head];
  assign mq_bank = mq_bank_r[mq_head];
  assign mq_offset = mq_offset_r[mq_head];

  // ---- lines and MSHRs -----------------------------------------------------------------------
  logic [31:0] tag_mem[ITEMS];  // the item a line holds or waits for
  logic [DW-1:0] data_mem[ITEMS];
  logic [ITEMS-1:0] allocated, valid;
  logic [ITEMS*WB-1:0] rank;  // line i's LRU order within its set (0 most recent) at i*WB
  logic [MISSES-1:0] busy, filled, keep;  // keep: the MSHR's line still waits for its fill
  logic [31:0] m_item[MISSES];
  logic [LW-1:0] m_line[MISSES];
  logic [DW-1:0] m_words[MISSES];
  logic [RW+TW-1:0] tgt_mem[MISSES * TARGETS];  // targets: requester, tag
  logic [GW-1:0] tgt_head[MISSES];
  logic [GW:0] tgt_count[MISSES];
  logic [MW-1:0] fl_q[MISSES];  // the filled FIFO: MSHRs with data, in fill order
  logic [MW-1:0] fl_head;
  logic [MW:0] fl_count;

  // A target's slot in tgt_mem; the slot `n` after `head` in an MSHR's ring of TARGETS.
  localparam int SLW = MISSES * TARGETS > 1 ? $clog2(MISSES * TARGETS) : 1;
  function automatic logic [SLW-1:0] slot(input logic [MW-1:0] m, input logic [GW-1:0] i);
    slot = SLW'(32'(m) * TARGETS + 32'(i));
  endfunction
  function automatic logic [GW-1:0] tgt_next(input logic [GW-1:0] head, input logic [GW:0] n);
    tgt_next = GW'((32'(head) + 32'(n)) % TARGETS);
  endfunction

  // ---- 1. fill ---------------------------------------------------------------------------------
  logic fill_now;
  logic [MW-1:0] f_tag;
  logic [DW-1:0] f_words;
  logic f_line_write;
  assign fill_now = fq_count != '0;
  assign f_tag = fq_tag[fq_head];
  assign f_words = fq_words[fq_head];
  assign f_line_write = fill_now && keep[f_tag];

  // ---- 2. deliver ------------------------------------------------------------------------------
  logic deliver;
  logic [MW-1:0] d_id;
  logic [DW-1:0] d_words;
  logic d_last;
  logic [RW+TW-1:0] d_target;
  assign deliver = fl_count != '0 || fill_now;
  assign d_id = fl_count != '0 ? fl_q[fl_head] : f_tag;
  assign d_words = fill_now && d_id == f_tag ? f_words : m_words[d_id];
  assign d_target = tgt_mem[slot(d_id, tgt_head[d_id])];
  assign d_last = tgt_count[d_id] == (GW + 1)'(1);

  // ---- 3. lookup -------------------------------------------------------------------------------
  logic head_any;
  logic [31:0] l_index;
  logic [LW-1:0] set_base, ways_mask;
  logic [WB:0] ways;
  logic match;
  logic [LW-1:0] l_line;          // the matching line
  logic l_valid;                  // its data present (a fill this cycle included)
  logic pend_any;
  logic [MW-1:0] pend_id;         // the MSHR the matching line waits for
  logic [LW-1:0] victim;
  logic [MW-1:0] free_id;
  logic free_any;
  logic do_hit, do_merge, do_miss, accept;
  logic [MW-1:0] merge_id, victim_pend_id;
  logic victim_pend;
  logic [LW-1:0] touched;  // the line whose LRU rank the lookup refreshes
  assign touched = do_miss ? victim : l_line;
  // The ranks after reset: each set's ways in way order (a function of the configuration, called
  // only in reset: as a combinational block it would be evaluated with every input change).
  function automatic logic [ITEMS*WB-1:0] ranks_at_reset(input logic [WB-1:0] mask);
    for (int i = 0; i < ITEMS; i++) ranks_at_reset[i*WB+:WB] = WB'(i) & mask;
  endfunction
  assign head_any = rq_count != '0;
  assign l_index = rq_index[rq_head];
  assign ways = (WB + 1)'(1) << cfg_ways_log2;
  always_comb begin
    logic [LW-1:0] set_mask;
    set_mask = LW'((33'd1 << (cfg_lines_log2 - cfg_ways_log2)) - 33'd1);
    ways_mask = LW'(ways) - LW'(1);
    set_base = LW'(l_index & 32'(set_mask)) << cfg_ways_log2;
  end

  // The set's ways: a match (at most one way holds an item), the first empty way, the LRU way.
  always_comb begin
    logic empty_any;
    logic [LW-1:0] empty_line, lru_line;
    match = 1'b0;
    l_line = set_base;
    empty_any = 1'b0;
    empty_line = set_base;
    lru_line = set_base;
    for (int w = WAYS - 1; w >= 0; w--) begin
      logic [LW-1:0] line;
      line = set_base | LW'(w);
      if ((WB + 1)'(w) < ways) begin
        if (allocated[line] && tag_mem[line] == l_index) begin
          match = 1'b1;
          l_line = line;
        end
        if (!allocated[line]) begin
          empty_any = 1'b1;
          empty_line = line;
        end
        if (rank[line*WB+:WB] == WB'(ways_mask)) lru_line = line;
      end
    end
    victim = empty_any ? empty_line : lru_line;
    l_valid = valid[l_line] || (f_line_write && m_line[f_tag] == l_line);
  end

  // The MSHRs: the one waiting for the matching line or for the victim (busy, not filled, its line
  // kept; this cycle's fill is no longer waiting), the lowest free one (deliver's freeing
  // included).
  always_comb begin
    pend_any = 1'b0;
    pend_id = '0;
    victim_pend = 1'b0;
    victim_pend_id = '0;
    free_any = 1'b0;
    free_id = '0;
    for (int m = MISSES - 1; m >= 0; m--) begin
      logic waiting_fill;
      waiting_fill = busy[m] && !filled[m] && keep[m] && !(fill_now && f_tag == MW'(m));
      if (waiting_fill && m_line[m] == l_line) begin
        pend_any = 1'b1;
        pend_id = MW'(m);
      end
      if (waiting_fill && m_line[m] == victim) begin
        victim_pend = 1'b1;
        victim_pend_id = MW'(m);
      end
      if (!busy[m] || (deliver && d_last && d_id == MW'(m))) begin
        free_any = 1'b1;
        free_id = MW'(m);
      end
    end
  end

  assign merge_id = FAULT_MERGE_WRONG && MISSES > 1 ? MW'((32'(pend_id) + 1) % MISSES) : pend_id;
  assign do_hit = head_any && match && l_valid && !deliver;
  assign do_merge = head_any && match && !l_valid && pend_any &&
                    tgt_count[merge_id] < (GW + 1)'(TARGETS);
  assign do_miss = head_any && !match && free_any && mq_count < (FW + 1)'(MEM_CAP);
  assign accept = do_hit || do_merge || do_miss;

  assign acc_valid = accept;
  assign acc_index = l_index;
  assign acc_requester = rq_requester[rq_head];
  assign acc_tag = rq_tag[rq_head];
  assign acc_kind = do_hit ? 2'd0 : do_merge ? 2'd1 : 2'd2;
  assign acc_mshr = do_hit ? '0 : do_merge ? merge_id : free_id;

  // The line request: bank 3 + i mod 3, offset base + (i div 3) * words (i div 3 as the product
  // with 2^33 / 3 rounded up, exact for every 32-bit i).
  logic [31:0] i_div3;
  logic [1:0] i_mod3;
  always_comb begin
    logic [64:0] p;
    p = 65'(l_index) * 65'h0AAAAAAAB;
    i_div3 = 32'(p >> 33);
    i_mod3 = 2'(l_index - i_div3 * 32'd3);
  end
  assign mreq_valid = do_miss;
  assign mreq_tag = free_id;
  assign mreq_bank = 3'd3 + 3'(i_mod3);
  assign mreq_offset = cfg_base + i_div3 * 32'(cfg_words);
  assign mreq_words = cfg_words;

  // ---- the response's delay line ---------------------------------------------------------------
  // Stage 0 takes this cycle's answer: a delivery's words, or a hit's line (its words come from
  // the data memory's registered read, or from this cycle's fill of that line) resolved at the
  // next stage.
  localparam int RS = HIT_LAT - 1;
  logic rs_valid[RS], rs_array[RS];
  logic [31:0] rs_index[RS];
  logic [RW-1:0] rs_requester[RS];
  logic [TW-1:0] rs_tag[RS];
  logic [DW-1:0] rs_words[RS];
  logic [DW-1:0] data_q, rs0_words;
  assign rs0_words = rs_array[0] ? data_q : rs_words[0];
  assign resp_valid = rs_valid[RS-1];
  assign resp_index = rs_index[RS-1];
  assign resp_requester = rs_requester[RS-1];
  assign resp_tag = rs_tag[RS-1];
  assign resp_words = RS == 1 ? rs0_words : rs_words[RS-1];

  always_ff @(posedge clk) begin
    data_q <= data_mem[l_line];
    if (f_line_write) data_mem[m_line[f_tag]] <= f_words;
    if (do_miss) tag_mem[victim] <= l_index;
    if (do_miss || do_merge)
      tgt_mem[do_miss ? slot(free_id, '0) : slot(merge_id, tgt_next(tgt_head[merge_id],
                                                                  tgt_count[merge_id]))] <=
          {rq_requester[rq_head], rq_tag[rq_head]};
    if (req_valid && req_ready) begin
      rq_index[QW'((QW + 1)'(rq_head) + rq_count)] <= req_index;
      rq_requester[QW'((QW + 1)'(rq_head) + rq_count)] <= req_requester;
      rq_tag[QW'((QW + 1)'(rq_head) + rq_count)] <= req_tag;
    end
    if (fill_valid && fill_ready) begin
      fq_tag[FW'((FW + 1)'(fq_head) + fq_count)] <= fill_tag;
      fq_words[FW'((FW + 1)'(fq_head) + fq_count)] <= fill_words;
    end
    if (do_miss) begin
      mq_tag_r[FW'((FW + 1)'(mq_head) + mq_count)] <= free_id;
      mq_bank_r[FW'((FW + 1)'(mq_head) + mq_count)] <= mreq_bank;
      mq_offset_r[FW'((FW + 1)'(mq_head) + mq_count)] <= mreq_offset;
    end
    if (fill_now) m_words[f_tag] <= f_words;
    if (do_miss) begin
      m_item[free_id] <= l_index;
      m_line[free_id] <= victim;
    end
    if (fill_now) fl_q[MW'((MW + 1)'(fl_head) + fl_count)] <= f_tag;
  end

  // The response stages (the words: no reset needed).
  always_ff @(posedge clk) begin
    rs_index[0] <= deliver ? m_item[d_id] : l_index;
    rs_requester[0] <= deliver ? d_target[RW+TW-1:TW] : rq_requester[rq_head];
    rs_tag[0] <= deliver ? d_target[TW-1:0] : rq_tag[rq_head];
    rs_words[0] <= do_hit ? f_words : d_words;  // a hit: the fill's words if it wrote the line
    for (int s = 1; s < RS; s++) begin
      rs_array[s] <= 1'b0;
      rs_index[s] <= rs_index[s-1];
      rs_requester[s] <= rs_requester[s-1];
      rs_tag[s] <= rs_tag[s-1];
      rs_words[s] <= s == 1 ? rs0_words : rs_words[s-1];
    end
    rs_array[0] <= do_hit && !(f_line_write && m_line[f_tag] == l_line);
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      for (int s = 0; s < RS; s++) rs_valid[s] <= 1'b0;
      rq_head <= '0;
      rq_count <= '0;
      fq_head <= '0;
      fq_count <= '0;
      mq_head <= '0;
      mq_count <= '0;
      fl_head <= '0;
      fl_count <= '0;
      allocated <= '0;
      valid <= '0;
      busy <= '0;
      filled <= '0;
      keep <= '0;
      for (int m = 0; m < MISSES; m++) begin
        tgt_head[m] <= '0;
        tgt_count[m] <= '0;
      end
      rank <= ranks_at_reset(WB'(ways_mask));
    end else begin
      rs_valid[0] <= deliver || do_hit;
      for (int s = 1; s < RS; s++) rs_valid[s] <= rs_valid[s-1];
      rq_count <= rq_count + (QW + 1)'(req_valid && req_ready) - (QW + 1)'(accept);
      if (accept) rq_head <= QW'((32'(rq_head) + 1) % REQ_CAP);
      fq_count <= fq_count + (FW + 1)'(fill_valid && fill_ready) - (FW + 1)'(fill_now);
      if (fill_now) fq_head <= FW'((32'(fq_head) + 1) % MEM_CAP);
      mq_count <= mq_count + (FW + 1)'(do_miss) - (FW + 1)'(mem_take && mq_valid);
      if (mem_take && mq_valid) mq_head <= FW'((32'(mq_head) + 1) % MEM_CAP);
      // 1. fill
      if (fill_now) filled[f_tag] <= 1'b1;
      if (f_line_write) valid[m_line[f_tag]] <= 1'b1;
      // 2. deliver (the filled FIFO takes this cycle's fill behind the ones before it)
      fl_count <= fl_count + (MW + 1)'(fill_now) - (MW + 1)'(deliver && d_last);
      if (deliver) begin
        tgt_head[d_id] <= tgt_next(tgt_head[d_id], (GW + 1)'(1));
        tgt_count[d_id] <= tgt_count[d_id] - (GW + 1)'(1);
        if (d_last) begin
          busy[d_id] <= 1'b0;
          fl_head <= MW'((32'(fl_head) + 1) % MISSES);
        end
      end
      // 3. lookup (after deliver: a miss may take the MSHR deliver freed)
      if (do_merge) tgt_count[merge_id] <= tgt_count[merge_id] + (GW + 1)'(1);
      if (do_miss) begin
        busy[free_id] <= 1'b1;
        filled[free_id] <= 1'b0;
        keep[free_id] <= 1'b1;
        tgt_head[free_id] <= '0;
        tgt_count[free_id] <= (GW + 1)'(1);
        if (victim_pend) keep[victim_pend_id] <= 1'b0;
        allocated[victim] <= 1'b1;
        valid[victim] <= 1'b0;
      end
      // The LRU order of the touched line's set: the line becomes the most recent, the ones
      // more recent than it move one down.
      if (accept) begin
        for (int w = 0; w < WAYS; w++) begin
          logic [LW-1:0] other;
          other = (touched & ~ways_mask) | LW'(w);
          if ((WB + 1)'(w) < ways && rank[other*WB+:WB] < rank[touched*WB+:WB])
            rank[other*WB+:WB] <= rank[other*WB+:WB] + WB'(1);
        end
        rank[touched*WB+:WB] <= '0;
      end
    end
  end
endmodule

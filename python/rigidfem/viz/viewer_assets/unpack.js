// Unpacks the viewer's scripts (three.js, its orbit controls and viewer.js, packed by rigidfem.view as a zlib stream
// in base64: 28 % of their size) and runs them, synchronously, where the page holds them: the page is ready by its
// load event, as with the scripts inline, and any browser runs it.

// A zlib stream (RFC 1950) decoded: its two-byte header, raw DEFLATE (RFC 1951: stored, fixed-code and dynamic-code
// blocks) and the Adler-32 of what it holds, checked, so that a damaged stream is an error rather than wrong text.
// Bits are read from each byte's least significant end; a Huffman code is canonical (RFC 1951 3.2.2) and is read
// bit by bit, most significant first, against the first code of each length.
function rigidfemInflate(input) {
  const LBASE = [3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163,
                 195, 227, 258];
  const LEXTRA = [0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0];
  const DBASE = [1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193, 257, 385, 513, 769, 1025, 1537, 2049, 3073,
                 4097, 6145, 8193, 12289, 16385, 24577];
  const DEXTRA = [0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13];
  const ORDER = [16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15];  // of the code-length code
  let pos = 2, bit = 0;  // the next byte and the next bit in it (after the header)
  let out = new Uint8Array(4 * input.length + 1024), n = 0;
  const fail = (what) => { throw new Error("unpack: " + what + " at byte " + pos + " of " + input.length); };
  function bits(k) {  // k bits as a number, the first read the least significant
    let v = 0;
    for (let i = 0; i < k; ++i) {
      if (pos >= input.length) fail("the stream ends early");
      v |= ((input[pos] >> bit) & 1) << i;
      if (++bit === 8) bit = 0, ++pos;
    }
    return v;
  }
  function room(k) {
    if (n + k <= out.length) return;
    const bigger = new Uint8Array(Math.max(2 * out.length, n + k));
    bigger.set(out.subarray(0, n));
    out = bigger;
  }
  // The canonical code of the symbols' code lengths (0: unused): count[L] codes of length L, and the symbols in
  // code order (by length, then by symbol). A code must fill its space (Kraft's sum 1), as zlib asks: only a single
  // code of one bit may leave half of it, and none at all is a code no symbol uses.
  function huffman(lengths, what) {
    const count = new Array(16).fill(0), start = new Array(16).fill(0), symbols = [];
    for (const L of lengths) ++count[L];
    count[0] = 0;
    let left = 1;  // codes of the current length not yet taken
    for (let L = 1; L < 16; ++L) {
      left = 2 * left - count[L];
      if (left < 0) fail("an over-subscribed " + what + " code");
    }
    const used = lengths.length - lengths.filter((L) => L === 0).length;
    if (left > 0 && used > 0 && !(used === 1 && count[1] === 1 && what !== "code-length"))
      fail("an incomplete " + what + " code");
    for (let L = 1; L < 16; ++L) start[L] = start[L - 1] + count[L - 1];
    lengths.forEach((L, s) => { if (L) symbols[start[L]++] = s; });
    return { count, symbols };
  }
  function decode(h) {
    let code = 0, first = 0, index = 0;  // the bits read; the first code of this length; the symbols of shorter codes
    for (let L = 1; L < 16; ++L) {
      if (pos >= input.length) fail("the stream ends early");
      code |= (input[pos] >> bit) & 1;  // bits(1), written out: the decoder's inner loop
      if (++bit === 8) bit = 0, ++pos;
      const k = h.count[L];
      if (code < first + k) return h.symbols[index + code - first];
      index += k;
      first = (first + k) << 1;
      code <<= 1;
    }
    return fail("a code outside the table");
  }
  function block(lit, dist) {  // literals and <length, distance> pairs up to the end of block (256)
    for (;;) {
      const s = decode(lit);
      if (s < 256) {
        room(1);
        out[n++] = s;
      } else if (s === 256) {
        return;
      } else {
        if (s > 285) fail("a length code " + s);
        const length = LBASE[s - 257] + bits(LEXTRA[s - 257]);
        const d = decode(dist);
        if (d > 29) fail("a distance code " + d);
        const back = DBASE[d] + bits(DEXTRA[d]);
        if (back > n) fail("a distance beyond the start");
        room(length);
        for (let i = 0; i < length; ++i, ++n) out[n] = out[n - back];  // may overlap what it writes
      }
    }
  }
  if (input.length < 2 || (input[0] & 15) !== 8 || input[0] >> 4 > 7 || (input[1] & 32) ||
      ((input[0] << 8) | input[1]) % 31) fail("a zlib header");
  let fixed = null;
  for (let last = 0; !last;) {
    last = bits(1);
    const type = bits(2);
    if (type === 0) {  // stored: from the next byte, LEN and its complement, then LEN bytes
      if (bit) bit = 0, ++pos;
      if (pos + 4 > input.length) fail("the stream ends early");
      const len = input[pos] | (input[pos + 1] << 8), nlen = input[pos + 2] | (input[pos + 3] << 8);
      if ((len ^ 0xffff) !== nlen) fail("a stored block's length");
      pos += 4;
      if (pos + len > input.length) fail("the stream ends early");
      room(len);
      out.set(input.subarray(pos, pos + len), n);
      n += len, pos += len;
    } else if (type === 1) {  // the fixed codes: literal/length 8, 9, 7, 8 bits by ranges; distances 5 bits
      if (!fixed) {
        const L = [];
        for (let s = 0; s < 288; ++s) L.push(s < 144 ? 8 : s < 256 ? 9 : s < 280 ? 7 : 8);
        fixed = [huffman(L, "literal/length"), huffman(new Array(32).fill(5), "distance")];  // 30, 31: never met
      }
      block(fixed[0], fixed[1]);
    } else if (type === 2) {  // dynamic: the code lengths, themselves coded, then the block
      const nlit = bits(5) + 257, ndist = bits(5) + 1, ncode = bits(4) + 4;
      if (nlit > 286 || ndist > 30) fail("more literal/length or distance codes than there are");
      const codeLengths = new Array(19).fill(0);
      for (let i = 0; i < ncode; ++i) codeLengths[ORDER[i]] = bits(3);
      const lengthCode = huffman(codeLengths, "code-length"), lengths = [];
      while (lengths.length < nlit + ndist) {
        const s = decode(lengthCode);
        if (s < 16) lengths.push(s);
        else if (s === 16) {  // the previous length 3-6 times
          if (!lengths.length) fail("a repeat with no length before it");
          const previous = lengths[lengths.length - 1];
          for (let r = 3 + bits(2); r > 0; --r) lengths.push(previous);
        } else {
          for (let r = s === 17 ? 3 + bits(3) : 11 + bits(7); r > 0; --r) lengths.push(0);  // zeros: 3-10, 11-138
        }
      }
      if (lengths.length > nlit + ndist) fail("code lengths beyond their count");
      if (!lengths[256]) fail("no end-of-block code");
      block(huffman(lengths.slice(0, nlit), "literal/length"), huffman(lengths.slice(nlit), "distance"));
    } else {
      fail("a block of type 3");
    }
  }
  if (bit) bit = 0, ++pos;  // the Adler-32 starts at the next byte
  if (pos + 4 > input.length) fail("the stream ends early");
  let a = 1, b = 0;  // Adler-32 (RFC 1950 9): two sums modulo 65521, reduced every 5552 bytes as zlib does
  for (let i = 0; i < n;) {
    for (const end = Math.min(n, i + 5552); i < end; ++i) a += out[i], b += a;
    a %= 65521, b %= 65521;
  }
  const stored = ((input[pos] << 24) | (input[pos + 1] << 16) | (input[pos + 2] << 8) | input[pos + 3]) >>> 0;
  if (((b << 16) | a) >>> 0 !== stored) fail("a checksum that does not match (the stream is damaged)");
  return out.subarray(0, n);
}

function rigidfemUnpack(packed) {
  "use strict";
  const status = document.body.dataset;
  // an error of three.js or viewer.js is recorded where viewer.js records its own (the body's data-error)
  window.addEventListener("error", (e) => { status.error = String(e.message || e); });
  const raw = atob(packed), bytes = new Uint8Array(raw.length);
  for (let i = 0; i < raw.length; ++i) bytes[i] = raw.charCodeAt(i);
  const script = document.createElement("script");
  script.textContent = new TextDecoder("utf-8", { fatal: true }).decode(rigidfemInflate(bytes));
  document.currentScript.after(script);  // runs now, in the page's order
}

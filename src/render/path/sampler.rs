//! Random numbers for light transport: Owen-scrambled, shuffled 2D Sobol points (Burley,
//! "Practical Hash-based Owen Scrambling", JCGT 2020), one independent scramble per
//! pixel and per pair of dimensions.
//!
//! Each pair of a path's dimensions (the pixel position, the lens, a light choice, a
//! bounce direction…) is a (0, 2)-sequence in its own right: the first `2^k` samples
//! of a pixel stratify every pair, so the error falls faster than independent random
//! numbers give, and the shuffle keeps different pairs from correlating. A sample is a
//! pure function of (pixel, sample index, dimension): the image is the same on any
//! thread count, and any subset of the samples can be rendered anywhere.

/// Pairs whose seeds a pixel keeps: the pixel position, the lens and four a surface for
/// eight bounces fit.
const KEPT_PAIRS: usize = 48;

/// The scrambling seeds of one pixel's pairs of dimensions. They depend on the pixel
/// and the pair, not the sample, so every sample of the pixel shares them: kept as far
/// as its paths have reached, three of a pair's five hashes are paid once a pixel
/// instead of once a number.
pub struct PixelSeeds {
    pixel: u32,
    kept: usize,
    seeds: [[u32; 3]; KEPT_PAIRS],
}

impl PixelSeeds {
    /// The seeds of the pixel numbered `pixel`, none computed yet.
    pub fn new(pixel: u32) -> PixelSeeds {
        PixelSeeds { pixel, kept: 0, seeds: [[0; 3]; KEPT_PAIRS] }
    }

    /// Pair `pair`'s seeds: the shuffle's, and the two dimensions' scrambles'.
    #[inline]
    fn get(&mut self, pair: u32) -> [u32; 3] {
        let k = pair as usize;
        if k < self.kept {
            return self.seeds[k];
        }
        let seed = hash(self.pixel ^ hash(pair.wrapping_add(0x9e37_79b9)));
        let seeds = [seed, hash(seed ^ 0x5bd1_e995), hash(seed ^ 0x27d4_eb2f)];
        // Pairs are drawn in order, so the one after the last kept is the next to keep.
        if k == self.kept && k < KEPT_PAIRS {
            self.seeds[k] = seeds;
            self.kept += 1;
        }
        seeds
    }
}

/// The numbers of one sample of one pixel, drawn in pairs.
pub struct Sampler<'s> {
    seeds: &'s mut PixelSeeds,
    /// The sample's index bit-reversed, which the shuffle of every pair takes.
    reversed: u32,
    pair: u32,
}

impl<'s> Sampler<'s> {
    /// Sample `index` of the pixel whose seeds are `seeds`.
    pub fn new(seeds: &'s mut PixelSeeds, index: u32) -> Sampler<'s> {
        Sampler { seeds, reversed: index.reverse_bits(), pair: 0 }
    }

    /// The next pair of numbers in `[0, 1)`.
    #[inline]
    pub fn next2(&mut self) -> (f32, f32) {
        let [shuffle, first, second] = self.seeds.get(self.pair);
        self.pair += 1;
        // The index shuffled: `nested_uniform_scramble(index, shuffle)`.
        let i = laine_karras(self.reversed, shuffle).reverse_bits();
        // The first dimension is `i` bit-reversed, so its scramble (which reverses its
        // input) takes `i` itself; the second's table holds its numbers reversed. The same
        // numbers as `nested_uniform_scramble` of each, with two bit reversals fewer (x86
        // has no instruction for one).
        let x = laine_karras(i, first).reverse_bits();
        let y = laine_karras(sobol_second_reversed(i), second).reverse_bits();
        (unit(x), unit(y))
    }
}

/// A 32-bit fraction as a float in `[0, 1)` (rounded down, never to 1).
fn unit(x: u32) -> f32 {
    ((x >> 8) as f32) * (1.0 / (1u32 << 24) as f32)
}

/// The Sobol sequence's second dimension, for the tests: [`sobol_second_reversed`]
/// reversed back.
#[cfg(test)]
fn sobol_second(index: u32) -> u32 {
    sobol_second_reversed(index).reverse_bits()
}

/// The Sobol sequence's second dimension (generator polynomial `x + 1`) bit-reversed,
/// which is what its scramble takes: the XOR of the direction numbers of `index`'s set
/// bits, a byte at a time from [`SOBOL_SECOND_REVERSED`]. The shuffled index is a full
/// 32-bit number, and a loop over its bits (the definition, kept in the tests) was a
/// fifth of the path loop's samples in `perf record` of the Cornell box at 128² × 64 on
/// one thread.
fn sobol_second_reversed(index: u32) -> u32 {
    let t = &SOBOL_SECOND_REVERSED;
    t[0][(index & 0xff) as usize]
        ^ t[1][((index >> 8) & 0xff) as usize]
        ^ t[2][((index >> 16) & 0xff) as usize]
        ^ t[3][(index >> 24) as usize]
}

/// [`sobol_second_reversed`] of every byte in each of an index's four bytes: entry
/// `[k][b]` is the XOR of the direction numbers `v_{8k + j}` for the bits `j` set in `b`,
/// bit-reversed, where `v_j = v_{j−1} ^ (v_{j−1} >> 1)` from `v_0 = 2^31` (reversal
/// commutes with XOR).
static SOBOL_SECOND_REVERSED: [[u32; 256]; 4] = sobol_second_bytes();

const fn sobol_second_bytes() -> [[u32; 256]; 4] {
    let mut v = [0u32; 32];
    v[0] = 1 << 31;
    let mut j = 1;
    while j < 32 {
        v[j] = v[j - 1] ^ (v[j - 1] >> 1);
        j += 1;
    }
    let mut table = [[0u32; 256]; 4];
    let mut k = 0;
    while k < 4 {
        let mut b = 0;
        while b < 256 {
            let (mut out, mut bit) = (0u32, 0);
            while bit < 8 {
                if b & (1 << bit) != 0 {
                    out ^= v[8 * k + bit];
                }
                bit += 1;
            }
            table[k][b] = out.reverse_bits();
            b += 1;
        }
        k += 1;
    }
    table
}

/// Laine and Karras's hash-based Owen scramble of a bit-reversed value (Burley's
/// constants): each bit is flipped by a hash of the bits above it.
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// An Owen scramble of `x`'s bits, most significant first: the definition the sampler's
/// shortcuts are tested against.
#[cfg(test)]
fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// A 32-bit integer hash with good avalanche (Wellons's `lowbias32`).
pub fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first `2^k` points of every pair fall one in each of the `2^k` cells of any
    /// elementary interval layout `2^a × 2^b` with `a + b = k`: the (0, 2) property the
    /// scramble must keep.
    #[test]
    fn every_pair_is_stratified_like_a_0_2_sequence() {
        for pixel in [0u32, 7, 123_456] {
            for k in [4u32, 6] {
                let n = 1u32 << k;
                let points: Vec<Vec<(f32, f32)>> = (0..n)
                    .map(|i| {
                        let mut seeds = PixelSeeds::new(pixel);
                        let mut s = Sampler::new(&mut seeds, i);
                        (0..4).map(|_| s.next2()).collect()
                    })
                    .collect();
                for pair in 0..4 {
                    for a in 0..=k {
                        let (cols, rows) = (1u32 << a, 1u32 << (k - a));
                        let mut seen = vec![false; n as usize];
                        for p in &points {
                            let (x, y) = p[pair];
                            assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                            let cell = (x * cols as f32) as u32 + cols * (y * rows as f32) as u32;
                            assert!(
                                !seen[cell as usize],
                                "pixel {pixel}, pair {pair}: two points in one {cols}×{rows} cell"
                            );
                            seen[cell as usize] = true;
                        }
                    }
                }
            }
        }
    }

    /// The table gives the second dimension as its definition does: the XOR of the
    /// direction numbers of the index's set bits.
    #[test]
    fn the_second_dimension_by_bytes_is_the_definition() {
        let by_bits = |mut index: u32| {
            let (mut v, mut out) = (1u32 << 31, 0);
            while index != 0 {
                if index & 1 != 0 {
                    out ^= v;
                }
                index >>= 1;
                v ^= v >> 1;
            }
            out
        };
        let mut x = 1u32;
        for i in (0..4096).chain([u32::MAX, 1 << 31, 0x8000_0001]) {
            x = hash(x ^ i);
            assert_eq!(sobol_second(i), by_bits(i), "index {i}");
            assert_eq!(sobol_second(x), by_bits(x), "index {x}");
        }
    }

    /// The sampler's numbers are the definition's — a fresh scramble of the index, then
    /// of each dimension, with seeds hashed from pixel and pair — for every sample of a
    /// pixel sharing its kept seeds, and past the pairs it keeps.
    #[test]
    fn kept_seeds_give_the_definitions_numbers() {
        let definition = |pixel: u32, index: u32, pair: u32| {
            let seed = hash(pixel ^ hash(pair.wrapping_add(0x9e37_79b9)));
            let i = nested_uniform_scramble(index, seed);
            let x = nested_uniform_scramble(i.reverse_bits(), hash(seed ^ 0x5bd1_e995));
            let y = nested_uniform_scramble(sobol_second(i), hash(seed ^ 0x27d4_eb2f));
            (unit(x), unit(y))
        };
        for pixel in [0u32, 99, 65_535] {
            let mut seeds = PixelSeeds::new(pixel);
            // Samples reaching different depths, so some find their seeds kept and some
            // keep them.
            for (index, pairs) in [(0u32, 3u32), (1, 10), (5, 2), (u32::MAX, KEPT_PAIRS as u32 + 7), (77, 60)] {
                let mut s = Sampler::new(&mut seeds, index);
                for pair in 0..pairs {
                    assert_eq!(s.next2(), definition(pixel, index, pair), "pixel {pixel}, sample {index}, pair {pair}");
                }
            }
        }
    }

    /// Different pixels and different pairs get different points: the scrambles are
    /// independent, not one pattern repeated.
    #[test]
    fn pixels_and_pairs_are_scrambled_apart() {
        let first = |pixel, pair| {
            let mut seeds = PixelSeeds::new(pixel);
            let mut s = Sampler::new(&mut seeds, 0);
            (0..pair).for_each(|_| {
                s.next2();
            });
            s.next2()
        };
        assert_ne!(first(0, 0), first(1, 0));
        assert_ne!(first(0, 0), first(0, 1));
        // The mean of many pixels' first points is near the middle.
        let n = 4096;
        let mean = (0..n).map(|p| first(p, 2).0).sum::<f32>() / n as f32;
        assert!((mean - 0.5).abs() < 0.02, "mean {mean}");
    }
}

// Part of the model (docs/energy-compensation.md, "The rough dielectric"): the
// energy compensation of the 2015 solid (Kulla & Conty 2017), over a number
// type F, its derivatives included (dual numbers interpolate the tables with
// their tangents).
//
// A rough interface of relative index η returns E_η(μo) of the light from
// outside (reflection and transmission, importance mode) and E_1/η(μo) from
// inside; the rest scattered between its microfacets more than once. Lobes
// cosine-shaped in each direction give it back (m = 1 - E, m̄ = 1 - Ē, Ē =
// 2 ∫ E μ dμ, each read on its own side):
//   reflection on the viewer's side   w_T (1 - b_v) m_v(μo) m_v(μi) / (π m̄_v)
//   transmission across               w_T b_v c m_v(μo) m_l(μi) / (π m̄_l)
// (importance mode; radiance mode divides the transmission by η_t², as the
// single-scattering transmission), so that the light added from either side is
// exactly (1 - b_v + b_v) m_v(μo) = 1 - E(μo) for a white interface (c = 1).
// Generalised reciprocity, f(wi, wo) / n(wi)² = f(wo, wi) / n(wo)² in
// importance mode, holds for the transmission when b_o m̄_o = η² b_i m̄_i (o
// outside, i inside). With the mean Fresnel transmittance T̄ of the outside
// (1 - F̄(η), F̄(η) = (η - 1) / (4.08567 + 1.00071 η), Kulla & Conty 2017) and
// T̄ / η² of the inside (a smooth interface's, by the same reciprocity), the
// split
//   b_o = T̄ m̄_i / (m̄_o + m̄_i),   b_i = (T̄ / η²) m̄_o / (m̄_o + m̄_i)
// satisfies it, and each is at most its side's mean transmittance.
//
// The metal part of the material (metallic m) takes the conductor's lobe of
// Kulla & Conty (model/energy.hpp's, with F_avg = (20 base_color + 1) / 21),
// from its own table of the 2015 specular's white conductor on the same nodes.
//
// The tables (principled_brdf/dielectric_energy_tables.hpp) are linear in r,
// in sqrt(x), x = (η - 1) / (η + 1), and in the cosine: μ outside, and inside
// q = (1 - μ) / (1 - μc) above the critical cosine μc = sqrt(1 - 1/η²) =
// 2 sqrt(x) / (1 + x), 2 - μ / μc below it, so that the edge of total internal
// reflection is a node for every η (rows of neighbouring η interpolate
// between curves whose edges coincide). Anisotropic materials read them at
// r_eff = (ax ay)^(1/4), the roughness itself. The number type provides
// floor_of (x >= 0) and table_pair ((table[i], table[i + 1]) for a whole i held
// as a real); a dual number's node is found from its real part.
#pragma once  // once per translation unit: included only by model.hpp, which allows one namespace

template <class F>
PB_MODEL_INLINE F real_part(const F& x) {
    return x;
}

template <class F>
using RealOf = decltype(real_part(F()));

// Where y in [0, nodes - 1] lies: the node below (at most nodes - 2) and how far past it.
// Any other y (NaN included, whatever the instruction set's min and max make of it)
// reads some node of the table, never one outside it.
template <class F>
struct TableNode {
    RealOf<F> index;
    F fraction;
};

template <class F>
PB_MODEL_INLINE TableNode<F> table_node(F y, int nodes) {
    using R = RealOf<F>;
    R whole = floor_of(real_part(y));
    R index = select(whole >= R(0.0), min(whole, R(double(nodes - 2))), R(0.0));
    return {index, y - F(index)};
}

// A row of kCosines nodes and the next row in r, at a fraction `along_r` between
// them, read at y in [0, kCosines - 1] in the row's nodes.
template <class F>
PB_MODEL_INLINE F bilinear_in_cosine_and_roughness(const float* table, RealOf<F> row, F along_r, F y) {
    using R = RealOf<F>;
    TableNode<F> m = table_node(y, energy::kCosines);
    R at = row + m.index;
    auto line = [&](R offset) {
        const auto [below, above] = table_pair(table, at + offset);
        return mix(F(below), F(above), m.fraction);
    };
    return mix(line(R(0.0)), line(R(double(energy::kCosines))), along_r);
}

// What a 2015 solid reads of the compensation: nothing added where the weights are 0
// (the option off, or a thin sheet).
template <class F>
struct DielectricCompensation {
    using R = RealOf<F>;
    F weight = F(0.0);       // w_T under the option
    F metal = F(0.0);        // metallic under the option
    R row = R(0.0);          // the material's row (η_k, r_j) in a side's interface table
    R conductor_row = R(0.0);  // its row r_j in the conductor's
    F along_r, along_x;
    F critical, above_critical, below_critical;  // μc, 1 / (1 - μc), 1 / μc: the inside's q
    F inv_pi_missing_average[2];  // 1 / (π m̄) outside, inside
    F transmitted[2];             // b outside, inside
    Rgb<F> metal_color;           // m F_avg² E_avg / (1 - F_avg (1 - E_avg)) / (π (1 - E_avg))
    F metal_albedo_scale;         // lum(m F_avg² E_avg / (1 - F_avg (1 - E_avg)))

    PB_MODEL_INLINE bool active() const { return nonzero_anywhere(weight) || nonzero_anywhere(metal); }

    // 1 - E(μ) of the interface on a side (inside: that of 1/η, its nodes in q)
    PB_MODEL_INLINE F interface_missing(F mu, const MaskOf<F>& inside) const {
        const float* table = energy::kInterfaceMissing[0];
        F q = select(mu >= critical, (F(1.0) - mu) * above_critical, neg_mul_add(mu, below_critical, F(2.0)));
        F y = select(inside, min(max(q, F(0.0)), F(2.0)) * F(0.5 * (energy::kCosines - 1)), cosine_node(mu));
        R side = select(inside, R(double(energy::kInterfaceSide)), R(0.0));
        constexpr double next_ior = energy::kEnergyRoughnesses * energy::kCosines;
        F below = bilinear_in_cosine_and_roughness(table, row + side, along_r, y);
        F above = bilinear_in_cosine_and_roughness(table, row + side + R(next_ior), along_r, y);
        return mix(below, above, along_x);
    }

    PB_MODEL_INLINE F conductor_missing(F mu) const {
        return bilinear_in_cosine_and_roughness(energy::kConductorMissing, conductor_row, along_r, cosine_node(mu));
    }

    // μ in [0, 1] (clamped) as nodes i / (kCosines - 1)
    static PB_MODEL_INLINE F cosine_node(F mu) { return min(max(mu, F(0.0)), F(1.0)) * F(double(energy::kCosines - 1)); }
};

// The compensation's constants of a 2015 solid of kParamSlots values p (params.hpp), given
// its interface's η and w_T.
template <class F>
PB_MODEL_INLINE DielectricCompensation<F> dielectric_compensation_of(const F* p, F eta, F eta_minus_one,
                                                                     F transmission_weight) {
    using R = RealOf<F>;
    F zero(0.0), one(1.0);
    DielectricCompensation<F> c;
    c.weight = transmission_weight;
    c.metal = p[kMetallic];
    TableNode<F> r = table_node(min(max(p[kRoughness], zero), one) * F(double(energy::kEnergyRoughnesses - 1)),
                                energy::kEnergyRoughnesses);
    F x = min(eta_minus_one / (eta_minus_one + F(2.0)), F(double(energy::kLargestX)));
    F root_x = square_root(x);  // the η nodes are uniform in sqrt(x)
    TableNode<F> k = table_node(root_x * F(double(energy::kIors - 1) / std::sqrt(double(energy::kLargestX))),
                                energy::kIors);
    c.along_r = r.fraction;
    c.along_x = k.fraction;
    R node = k.index * R(double(energy::kEnergyRoughnesses)) + r.index;  // (k, j) in the averages
    c.row = node * R(double(energy::kCosines));
    c.conductor_row = r.index * R(double(energy::kCosines));
    c.critical = F(2.0) * root_x / (one + x);  // sqrt(1 - 1/η²) at the tables' η = (1 + x) / (1 - x)
    c.above_critical = one / (one - c.critical);
    c.below_critical = one / c.critical;
    auto average = [&](const float* table) {  // at (x, r), bilinear like the rows it averages
        const auto [a, b] = table_pair(table, node);
        const auto [c0, d] = table_pair(table, node + R(double(energy::kEnergyRoughnesses)));
        return mix(mix(F(a), F(b), r.fraction), mix(F(c0), F(d), r.fraction), k.fraction);
    };
    F missing_outside = max(average(energy::kOutsideMissingAverage), F(1e-7));
    // the inside's mean at the material's μc: (1 - μc) A - (1 - μc)² B + μc² C
    F above = one - c.critical;
    F moments_a = average(energy::kInsideMoments[0]), moments_b = average(energy::kInsideMoments[1]);
    F moments_c = average(energy::kInsideMoments[2]);
    F missing_inside = max(mul_add(c.critical * c.critical, moments_c, above * neg_mul_add(above, moments_b, moments_a)),
                           F(1e-7));
    c.inv_pi_missing_average[0] = F(kInvPi) / missing_outside;
    c.inv_pi_missing_average[1] = F(kInvPi) / missing_inside;
    F mean_transmittance = one - eta_minus_one / mul_add(F(1.00071), eta, F(4.08567));
    F share = one / (missing_outside + missing_inside);
    c.transmitted[0] = mean_transmittance * missing_inside * share;
    c.transmitted[1] = mean_transmittance / (eta * eta) * missing_outside * share;

    // the metal: model/energy.hpp's factor with F_avg = (20 base_color + 1) / 21, at most 1
    const auto [conductor_below, conductor_above] = table_pair(energy::kConductorMissingAverage, r.index);
    F missing_average = mix(F(conductor_below), F(conductor_above), r.fraction);
    F e_average = one - missing_average;
    auto factor = [&](F base) {
        F f_avg = min(mul_add(F(20.0 / 21.0), base, F(1.0 / 21.0)), one);
        return c.metal * f_avg * f_avg * e_average / neg_mul_add(f_avg, missing_average, one);
    };
    Rgb<F> tint{factor(p[kBaseColorR]), factor(p[kBaseColorG]), factor(p[kBaseColorB])};
    c.metal_albedo_scale = luminance_of(tint);
    c.metal_color = (F(kInvPi) / max(missing_average, F(1e-7))) * tint;
    return c;
}

// The compensation's factors at a pair (of Lobes2015's colors): grey reflected, the
// transmission color's, the metal color's.
template <class F>
struct CompensationValues {
    F reflected, transmitted, metal;
};

// At a pair seen from the viewer's side (`inside`), the light below it or not; μo, μi >= 0.
template <class F>
PB_MODEL_INLINE CompensationValues<F> compensation_values(const DielectricCompensation<F>& c, F mu_o, F mu_i,
                                                          const MaskOf<F>& inside, const MaskOf<F>& below,
                                                          F eta_t, TransportMode mode) {
    F zero(0.0), one(1.0);
    CompensationValues<F> out{zero, zero, zero};
    if (nonzero_anywhere(c.weight)) {
        MaskOf<F> light_inside = (inside & !below) | (!inside & below);
        F missing = c.interface_missing(mu_o, inside) * c.interface_missing(mu_i, light_inside);
        F norm = select(light_inside, c.inv_pi_missing_average[1], c.inv_pi_missing_average[0]);
        F transmitted = select(inside, c.transmitted[1], c.transmitted[0]);
        F value = c.weight * missing * norm;
        out.reflected = select(below, zero, value * (one - transmitted));
        F through = value * transmitted;
        if (mode == TransportMode::kRadiance) through = through / (eta_t * eta_t);
        out.transmitted = select(below, through, zero);
    }
    if (nonzero_anywhere(c.metal))
        out.metal = select(inside | below, zero, c.conductor_missing(mu_o) * c.conductor_missing(mu_i));
    return out;
}

// The sampling mixture's weights of the added lobes at the view (docs/sampling.md):
// the reflected ones join the cosine lobe, the transmitted one is drawn by a
// cosine below (the thin sheet's diffuse transmission's draw).
template <class F>
struct CompensationWeights {
    F reflected, transmitted;
};

template <class F>
PB_MODEL_INLINE CompensationWeights<F> compensation_weights(const DielectricCompensation<F>& c, F mu_o,
                                                            const MaskOf<F>& inside, F transmitted_luminance) {
    F zero(0.0), one(1.0);
    CompensationWeights<F> out{zero, zero};
    if (nonzero_anywhere(c.weight)) {
        F missing = c.weight * c.interface_missing(mu_o, inside);
        F transmitted = select(inside, c.transmitted[1], c.transmitted[0]);
        out = {missing * (one - transmitted), missing * transmitted * transmitted_luminance};
    }
    if (nonzero_anywhere(c.metal))
        out.reflected = out.reflected + select(inside, zero, c.metal_albedo_scale * c.conductor_missing(mu_o));
    return out;
}

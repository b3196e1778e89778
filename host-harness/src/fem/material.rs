//! Isotropic linear elastic material (Young's modulus, Poisson ratio).

/// Why a [`Material`] was rejected.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum MaterialError {
    /// Young's modulus must be finite and strictly positive (Pa).
    #[error("Young's modulus must be finite and > 0 Pa, got {0}")]
    YoungModulus(f64),
    /// Poisson ratio must satisfy `0 <= nu < 0.5`.
    #[error("Poisson ratio must satisfy 0 <= nu < 0.5, got {0}")]
    PoissonRatio(f64),
}

/// Isotropic linear elastic material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus `E`, Pa.
    pub young_pa: f64,
    /// Poisson ratio `nu`, dimensionless, `0 <= nu < 0.5`.
    pub poisson: f64,
}

impl Material {
    /// A material with Young's modulus `young_pa` (Pa, finite, `> 0`) and Poisson
    /// ratio `poisson` (`0 <= nu < 0.5`, incompressible `0.5` excluded).
    pub fn new(young_pa: f64, poisson: f64) -> Result<Self, MaterialError> {
        if !(young_pa.is_finite() && young_pa > 0.0) {
            return Err(MaterialError::YoungModulus(young_pa));
        }
        if !(poisson.is_finite() && (0.0..0.5).contains(&poisson)) {
            return Err(MaterialError::PoissonRatio(poisson));
        }
        Ok(Self { young_pa, poisson })
    }

    /// Lamé coefficients `(lambda, mu)` in Pa (`MODELS.md` §1):
    /// `lambda = E nu / ((1 + nu)(1 - 2 nu))`, `mu = E / (2 (1 + nu))`.
    pub fn lame(&self) -> (f64, f64) {
        palpate_kernel::math::element::lame(self.young_pa, self.poisson)
    }
}

/// The material of every tet of a mesh (heterogeneous tissue, e.g. a stiff nodule in soft
/// parenchyma): one [`Material`] per tet, in the mesh's tet order, and the default material
/// (the scene's `[material]`, which a table header records).
///
/// Every assembly of the P1 stiffness, the compliance, the tensor-mass tensors and the
/// St Venant-Kirchhoff terms takes this type; a homogeneous body is [`TetMaterials::uniform`],
/// the same code. Its length is the tet count of the mesh it was made for (the assemblies
/// check it).
#[derive(Debug, Clone, PartialEq)]
pub struct TetMaterials {
    default: Material,
    per_tet: Vec<Material>,
}

impl TetMaterials {
    /// Every one of `tet_count` tets of `material` (a homogeneous body).
    pub fn uniform(material: Material, tet_count: usize) -> Self {
        Self {
            default: material,
            per_tet: vec![material; tet_count],
        }
    }

    /// Per-tet materials from region ids: tet `t` takes the material `regions` gives its
    /// region `tet_regions[t]`, else `default`. One entry per tet of the mesh.
    pub fn from_regions(
        default: Material,
        tet_regions: &[u32],
        regions: &[(u32, Material)],
    ) -> Self {
        let per_tet = tet_regions
            .iter()
            .map(|id| {
                regions
                    .iter()
                    .find(|(region, _)| region == id)
                    .map_or(default, |&(_, m)| m)
            })
            .collect();
        Self { default, per_tet }
    }

    /// The materials of the tets `tets` (indices into this mesh's tets, in
    /// the order given): a sub-mesh's, the same default.
    pub fn subset(&self, tets: impl Iterator<Item = usize>) -> Self {
        Self {
            default: self.default,
            per_tet: tets.map(|t| self.per_tet[t]).collect(),
        }
    }

    /// The default material (the scene's `[material]`; the table header's `young_pa`,
    /// `poisson`).
    pub fn default_material(&self) -> Material {
        self.default
    }

    /// One material per tet, in tet order.
    pub fn per_tet(&self) -> &[Material] {
        &self.per_tet
    }

    /// The number of tets.
    pub fn len(&self) -> usize {
        self.per_tet.len()
    }

    /// `true` for a mesh without tets.
    pub fn is_empty(&self) -> bool {
        self.per_tet.is_empty()
    }

    /// Each tet's Lamé coefficients `[λ, μ]`, Pa (`MODELS.md` §1): the table's `tet-material`
    /// section.
    pub fn lame(&self) -> Vec<[f64; 2]> {
        self.per_tet
            .iter()
            .map(|m| {
                let (lambda, mu) = m.lame();
                [lambda, mu]
            })
            .collect()
    }

    /// `Err` naming both counts unless these are the materials of `tet_count` tets.
    pub fn check_tet_count(&self, tet_count: usize) -> anyhow::Result<()> {
        anyhow::ensure!(
            self.len() == tet_count,
            "the per-tet materials are for {} tets, the mesh has {tet_count}",
            self.len()
        );
        Ok(())
    }
}

//! Rigid bodies: their description and their state during a simulation.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// A rigid body of the vehicle.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Link name (from the URDF).
    pub name: String,
    /// Mass, kg.
    pub mass: f64,
    /// Principal moments of inertia about the body axes (x ahead, y left, z up), kg·m².
    pub inertia: Vector3<f64>,
    /// Centre of gravity in the vehicle frame at the static loaded position, m.
    pub position: Vector3<f64>,
}

impl Body {
    /// Half-lengths (x, y, z) of the uniform box with this body's mass and principal inertias,
    /// m: `L_x² = 6·(I_y + I_z − I_x)/m` and alike (a rough size for checking attachment points).
    pub fn half_extents(&self) -> Vector3<f64> {
        let i = self.inertia;
        let l = |a: f64, b: f64, c: f64| 0.5 * (6.0 * (b + c - a).max(0.0) / self.mass).sqrt();
        Vector3::new(l(i.x, i.y, i.z), l(i.y, i.z, i.x), l(i.z, i.x, i.y))
    }
}

/// Position, orientation and velocities of a body in the world frame (x, y horizontal, z up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyState {
    /// Centre of gravity, m.
    pub position: Vector3<f64>,
    /// Orientation of the body axes.
    pub rotation: UnitQuaternion<f64>,
    /// Velocity of the centre of gravity, m/s.
    pub velocity: Vector3<f64>,
    /// Angular velocity, world axes, rad/s.
    pub angular_velocity: Vector3<f64>,
}

impl BodyState {
    /// World position of a point given in body coordinates relative to the centre of gravity.
    #[inline]
    pub fn point(&self, local: &Vector3<f64>) -> Vector3<f64> {
        self.position + self.rotation * local
    }

    /// World velocity of a point given in body coordinates.
    #[inline]
    pub fn point_velocity(&self, local: &Vector3<f64>) -> Vector3<f64> {
        self.velocity + self.angular_velocity.cross(&(self.rotation * local))
    }

    /// Rotation matrix of the body axes.
    #[inline]
    pub fn matrix(&self) -> Matrix3<f64> {
        self.rotation.to_rotation_matrix().into_inner()
    }
}

/// Force and torque (about the centre of gravity) acting on a body, world axes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wrench {
    /// Force, N.
    pub force: Vector3<f64>,
    /// Torque about the centre of gravity, N·m.
    pub torque: Vector3<f64>,
}

impl Wrench {
    /// Adds a force acting at a world point of a body whose centre of gravity is `cg`.
    #[inline]
    pub fn add_at(&mut self, force: Vector3<f64>, point: Vector3<f64>, cg: Vector3<f64>) {
        self.force += force;
        self.torque += (point - cg).cross(&force);
    }
}

/// Attachment of an element to a body: the point in body coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Attachment {
    /// Body index.
    pub body: usize,
    /// Point relative to the body's centre of gravity, body axes, m.
    pub local: Vector3<f64>,
}

"""Pure geometry (numpy only): involutes, spherical involutes, ISO 606 forms, thermal model."""

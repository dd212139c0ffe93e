#include "app/wizard/CalibrationWizard.h"

int mirage::app::runCalibrationWizard(const WizardOptions&) {
    return 0;
}

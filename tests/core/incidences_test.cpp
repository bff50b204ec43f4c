// The default incidences and the incidence range: one owner, used by the simulator, the study and
// the command line.
#include "core/incidences.h"

#include "simulator/goniophotometer.h"
#include "study/settings.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

TEST(Incidences, DefaultsAreTheStudysSevenAnglesEverywhere) {
    const std::vector<double> expected = {0, 15, 30, 45, 60, 70, 80};  // the original study's
    EXPECT_EQ(default_incidences_deg(), expected);
    EXPECT_EQ(default_incidences_text(), "0,15,30,45,60,70,80");
    EXPECT_EQ(SimulationSettings{}.theta_i_deg, expected);
    EXPECT_EQ(StudySettings{}.reference.theta_i_deg, expected);
}

TEST(Incidences, RangeIsZeroToNinetyExcluded) {
    EXPECT_NO_THROW(check_incidence(0, "here", "--theta-i"));
    EXPECT_NO_THROW(check_incidence(89.99, "here", "--theta-i"));
    for (double bad : {90.0, -0.001, 1e308, double(NAN)}) {
        EXPECT_FALSE(incidence_in_range(bad)) << bad;
        try {
            check_incidence(bad, "file.csv", "row 3, theta_i");
            FAIL() << bad << " accepted";
        } catch (const InputError& e) {
            EXPECT_EQ(e.where(), "file.csv");
            EXPECT_EQ(e.field(), "row 3, theta_i");
            EXPECT_NE(e.problem().find("outside the allowed range [0, 90) degrees"),
                      std::string::npos)
                << e.problem();
        }
    }
}

}  // namespace
}  // namespace lamina
